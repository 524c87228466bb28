"""The local Dask cluster of a sweep is private: another client on the machine cannot connect
(TLS with a key pair made for the cluster), and it serves no dashboard or HTTP endpoint."""

import urllib.error
import urllib.request

import pytest

from weakgrid.sweep import open_client


def _double(x):
    return 2 * x


@pytest.mark.slow
def test_a_second_local_client_cannot_connect_and_nothing_is_served():
    from distributed import Client

    with open_client(workers=1) as client:
        assert client.submit(_double, 21).result() == 42     # the sweep's own client works
        addr = client.scheduler.address
        assert addr.startswith("tls://127.0.0.1:")
        host_port = addr.split("://", 1)[1]
        for other in (addr, "tcp://" + host_port):           # with and without TLS
            with pytest.raises(Exception):
                intruder = Client(other, timeout="3s")
                try:
                    intruder.submit(_double, 1).result(timeout=3)
                finally:
                    intruder.close()
        sched = client.cluster.scheduler
        port = sched.http_server.port if getattr(sched, "http_server", None) else None
        if port:
            for path in ("/status", "/json/identity.json", "/health", "/metrics"):
                with pytest.raises(urllib.error.HTTPError) as e:
                    urllib.request.urlopen(f"http://127.0.0.1:{port}{path}", timeout=3)
                assert e.value.code == 404
