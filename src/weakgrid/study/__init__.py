"""weakgrid.study — studies as data: a grid, a controlled machine, a UPQC, design settings,
controllers to compare, scenarios; and the engine that runs them (metrics, claims, figures,
report). The paper's two cases are two shipped study files (``weakgrid/data/studies``).

=================  ===========================================================================
module             what
=================  ===========================================================================
``studyfile``      reading and validating study files; dotted paths (``upqc.rating``)
``build``          the study's grid for the simulator at a load level / UPQC structure
``device``         the UPQC as a device: its power rating, losses, dc link; its power metrics
``controllers``    the controller registry (kind → builder), HJI training on the design model
``runner``         one (scenario, controller) run and its metrics
``engine``         every run of one or more studies, the mode check, files and report
``claims``         verdict rules referring to runs by id (the claims are data in studies)
``figures``        figures as data (panels × runs)
``report``         metrics tables and the HTML report
``reproduce``      the shipped studies marked ``reproduce = true``
=================  ===========================================================================

Layer: imports :mod:`weakgrid.design`, :mod:`weakgrid.sim` and :mod:`weakgrid.models` (and
through them :mod:`weakgrid.game`); imported only by :mod:`weakgrid.cli`.
"""
