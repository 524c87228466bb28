"""The local Dask cluster of a sweep is private: another client on the machine cannot connect
(TLS with a key pair made for the cluster), and it serves no dashboard or HTTP endpoint."""

import subprocess
import sys
import urllib.error
import urllib.request

import pytest

from weakgrid.sweep import open_client


def _double(x):
    return 2 * x


#: another process on the machine trying the cluster: connect, then run a task
INTRUDER = """
import sys
from distributed import Client
client = Client(sys.argv[1], timeout="3s")
print("RAN", client.submit(sum, [1, 2]).result(timeout=3))
"""


@pytest.mark.slow
def test_a_second_local_client_cannot_connect_and_nothing_is_served():
    with open_client(workers=1) as client:
        assert client.submit(_double, 21).result() == 42     # the sweep's own client works
        addr = client.scheduler.address
        assert addr.startswith("tls://127.0.0.1:")
        host_port = addr.split("://", 1)[1]
        # with and without TLS, each from its own process (as another user's would be; in
        # this process, a refused Client collected during the next one's start deadlocked
        # Dask's loop runner: Client.__del__ -> close -> LoopRunner.stop, CI 2026-12-07)
        for other in (addr, "tcp://" + host_port):
            p = subprocess.run([sys.executable, "-c", INTRUDER, other], capture_output=True,
                               text=True, timeout=120)
            assert p.returncode != 0 and "RAN" not in p.stdout, (other, p.stdout, p.stderr)
        sched = client.cluster.scheduler
        port = sched.http_server.port if getattr(sched, "http_server", None) else None
        if port:
            for path in ("/status", "/json/identity.json", "/health", "/metrics"):
                with pytest.raises(urllib.error.HTTPError) as e:
                    urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=3)
                assert e.value.code == 404
