"""Small test networks in MATPOWER form."""

import numpy as np


def two_machine_case(x_line=0.3, p=0.8):
    """Two buses, one line, a PV generator at bus 1 and the slack generator at bus 2 (MATPOWER form)."""
    bus = np.array([
        [1, 2, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
        [2, 3, 0, 0, 0, 0, 1, 1.0, 0, 110, 1, 1.5, 0.5],
    ], dtype=float)
    gen = np.array([
        [1, p * 100, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
        [2, 0, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
    ], dtype=float)
    branch = np.array([[1, 2, 0.0, x_line, 0.0, 0, 0, 0, 0, 0, 1, -360, 360]], dtype=float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def classical_smib(p=0.8, model="GENCLS", upqc_vmax=None, upqc_params=None, **params):
    """A machine (``model``, classical by default: Sn 100 MVA, M 6 s, x'd 0.25 pu) on a line
    (0.01 + j0.3 pu) to an infinite bus, set up; with ``upqc_vmax`` a conventional UPQC "U" on
    the line (further UPQC parameters: ``upqc_params``). The SMIB every engine (phasor, DPsim
    EMT and DP) is checked on."""
    from weakgrid.sim.sources import InfiniteBus
    from weakgrid.sim.system import System
    from weakgrid.sim.upqc import UPQC

    case = two_machine_case(x_line=0.3, p=p)
    case["branch"][0, 2] = 0.01
    s = System(case)
    s.add_machine(model, "G1", 0, **{**dict(Sn=100, M=6.0, D=0.0, ra=0.0, xd1=0.25), **params})
    src = InfiniteBus()
    src.add_source("S2", 1)
    s.add_component(src)
    if upqc_vmax is not None:
        s.add_component(UPQC()).add_upqc("U", branch=0, structure="conventional", Vmax=upqc_vmax,
                                             **(upqc_params or {}))
    s.setup()
    return s


#: case 1's synchronous machine and controls (src/weakgrid/data/studies/case1-weak-grid.toml), with
#: the GENROU unsaturated (S10 = 0: DPsim has no saturation)
CASE1_GENROU = dict(Sn=100, M=6.0, D=0.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7, xd1=0.3, xq1=0.55,
                    xd2=0.25, xq2=0.25, Td10=6.0, Td20=0.03, Tq10=0.4, Tq20=0.05, S10=0.0)
CASE1_EXDC2 = dict(TR=0.01, TA=0.04, TC=1.0, TB=1.0, TE=0.8, TF1=1.0, KF1=0.03, KA=40.0, KE=1.0,
                   VRMAX=7.3, VRMIN=-7.3, E1=2.8, SE1=0.04, E2=3.7, SE2=0.33)
CASE1_TGOV1 = dict(R=0.05, VMAX=1.2, VMIN=0.0, T1=0.1, T2=0.5, T3=2.0, Dt=0.0)
CASE1_IEEEST = dict(MODE=1, T1=0.15, T2=0.05, T3=0.15, T4=0.05, T5=2.0, T6=2.0, KS=10.0,
                    LSMAX=0.1, LSMIN=-0.1)


def machine_smib(model="GENROU", gen=None, exciter=("EXDC2", CASE1_EXDC2),
                 governor=("TGOV1", CASE1_TGOV1), pss=("IEEEST", CASE1_IEEEST), p=0.8):
    """The SMIB of :func:`classical_smib` with generator "G1" = ``model`` (case 1's GENROU by
    default) and its exciter, governor and stabilizer (``None`` leaves one out); set up."""
    from weakgrid.sim.sources import InfiniteBus
    from weakgrid.sim.system import System

    case = two_machine_case(x_line=0.3, p=p)
    case["branch"][0, 2] = 0.01
    s = System(case)
    s.add_generator("G1", 0, (model, CASE1_GENROU if gen is None else gen), exciter=exciter,
                    governor=governor, pss=pss)
    src = InfiniteBus()
    src.add_source("S2", 1)
    s.add_component(src)
    s.setup()
    return s


def gti_upqc_sg_case(p_gti=50.0):
    """GTI (bus 1) -- UPQC branch -- shunt bus r = 2 (load) -- line -- SG slack bus 3 (load)."""
    bus = np.array([
        [1, 2, 0, 0, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [2, 1, 30, 10, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
        [3, 3, 100, 30, 0, 0, 1, 1.0, 0, 20, 1, 1.5, 0.5],
    ], dtype=float)
    gen = np.array([
        [1, p_gti, 0, 999, -999, 1.0, 100, 1, 999, -999] + [0] * 11,
        [3, 0, 0, 999, -999, 1.02, 200, 1, 999, -999] + [0] * 11,
    ], dtype=float)
    branch = np.array([
        [2, 1, 0.002, 0.05, 0.0, 0, 0, 0, 0, 0, 1, -360, 360],     # UPQC series branch (r -> 1)
        [2, 3, 0.02, 0.20, 0.05, 0, 0, 0, 0, 0, 1, -360, 360],
    ], dtype=float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}


def build_gti_upqc_sg(structure="conventional", mode="energy", p_gti=50.0, upqc=None):
    """System with a GTI + UPQC + an SG (GENROU + SEXS + HYGOV + IEEEST); set up.
    ``upqc``: further UPQC parameters (chi, Cdc, Imax, Rsh, ...)."""
    from weakgrid.sim.gti import GTI
    from weakgrid.sim.system import System
    from weakgrid.sim.upqc import UPQC

    s = System(gti_upqc_sg_case(p_gti))
    s.add_generator("SG", 1,
                    machine=("GENROU", dict(Sn=200, M=8.0, D=0.0, ra=0.003, xl=0.15, xd=1.8, xq=1.7,
                                            xd1=0.3, xq1=0.55, xd2=0.25, xq2=0.25, Td10=6.0, Td20=0.03,
                                            Tq10=0.4, Tq20=0.05, S10=0.05, S12=0.3)),
                    exciter=("SEXS", dict(TATB=0.2, TB=10.0, K=100.0, TE=0.05, EMIN=0.0, EMAX=5.0)),
                    governor=("HYGOV", dict(R=0.05, r=0.4, Tr=5.0, Tf=0.05, Tg=0.5, VELM=0.2,
                                            GMAX=1.0, GMIN=0.0, Tw=1.0, At=1.2, qNL=0.08)),
                    pss=("IEEEST", dict(MODE=1, T1=0.15, T2=0.05, T3=0.15, T4=0.05, T5=2.0, T6=2.0,
                                        KS=10.0, LSMAX=0.1, LSMIN=-0.1)))
    gti = s.add_component(GTI())
    gti.add_gti("PV", gen=0, ref_bus=2, mode=mode, C=0.05, Vc0=1.0, chi=0.02, B=20.0, ks_max=1.5, tau=2.0)
    up = s.add_component(UPQC())
    up.add_upqc("U", branch=0, structure=structure, gti="PV" if structure == "reduced" else None, Vmax=0.2,
                **(upqc or {}))
    s.setup()
    return s


def psse_three_bus_case():
    """PSID's PSS/E benchmark network ``ThreeBusMulti.raw`` (tests/data/psid/GENROU/), by hand.

    PSS/E v33 raw, SBASE 100 MVA, 60 Hz, all buses 138 kV: bus 101 slack at 1.05 pu (its
    GENCLS with H = 0 is PSS/E's infinite bus), bus 102 PV at 1.02 pu with 100 MW (MBASE
    100 MVA, ZSORCE j0.25), bus 103 with a 250 MW + 30 Mvar load (constant impedance in
    the time domain, as PSID's tests convert it); three lines 0.01 + j0.12 pu, no charging:
    row 0 = 101-102 (the line PSID's tests trip), 1 = 101-103, 2 = 102-103.
    """
    bus = np.array([
        [101, 3, 0, 0, 0, 0, 1, 1.05, 0.0, 138, 1, 1.1, 0.9],
        [102, 2, 0, 0, 0, 0, 1, 1.02, -0.944, 138, 1, 1.1, 0.9],
        [103, 1, 250, 30, 0, 0, 1, 0.99341, -8.7697, 138, 1, 1.1, 0.9],
    ], dtype=float)
    gen = np.array([
        [101, 153.335, 73.271, 100, -100, 1.05, 100, 1, 318, 0] + [0] * 11,
        [102, 100.0, -3.247, 100, -100, 1.02, 100, 1, 318, 0] + [0] * 11,
    ], dtype=float)
    branch = np.array([[f, t, 0.01, 0.12, 0.0, 250, 250, 250, 0, 0, 1, -360, 360]
                       for f, t in ((101, 102), (101, 103), (102, 103))], dtype=float)
    return {"baseMVA": 100.0, "bus": bus, "gen": gen, "branch": branch}
