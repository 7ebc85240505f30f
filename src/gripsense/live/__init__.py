"""Live mode: friction from a receiver in real time (``gripsense live``)."""

from gripsense.live.incremental import LiveIngest
from gripsense.live.runner import recover, run_live
from gripsense.live.sources import ReplaySource, SerialSource, TcpSource

__all__ = ["LiveIngest", "ReplaySource", "SerialSource", "TcpSource", "recover", "run_live"]
