"""What fleet prints of Dask: nothing of its own lines, also while a slow worker is stopped."""

from __future__ import annotations

import io
import logging

import pytest

pytestmark = pytest.mark.slow  # starts a Dask LocalCluster


def test_a_worker_killed_at_the_close_prints_nothing(monkeypatch):
    """A worker that takes longer than Dask's 4 s to stop (a busy machine) is killed by its
    nanny with a WARNING; the cluster's close has by then lifted its silence of Dask's log
    handler. Reproduced here by that warning emitted at the end of the close: not a line of it
    reaches the terminal (a worker dying *during* the run is still said, in one line)."""
    from distributed import LocalCluster

    from gripsense.fleet.run import _client

    close = LocalCluster.close

    def slow_close(self, *args, **kwargs):
        out = close(self, *args, **kwargs)
        logging.getLogger("distributed.nanny").warning(
            "Worker process still alive after 4.0 seconds, killing"
        )
        return out

    monkeypatch.setattr(LocalCluster, "close", slow_close)
    # what Dask's own handlers (its terminal lines) receive, and what reaches the root logger
    seen = io.StringIO()
    for h in logging.getLogger("distributed").handlers:
        if isinstance(h, logging.StreamHandler):
            monkeypatch.setattr(h, "stream", seen)
    root = logging.StreamHandler(seen)
    logging.getLogger().addHandler(root)
    said = []
    try:
        with _client(None, 1, say=said.append) as client:
            assert client.submit(sum, [1, 2]).result(timeout=600) == 3
    finally:
        logging.getLogger().removeHandler(root)
    assert "killing" not in seen.getvalue(), seen.getvalue()
    assert said == []
