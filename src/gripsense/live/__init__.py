"""Live mode: friction from a receiver in real time (``gripsense live``)."""

from gripsense.live.incremental import LiveIngest
from gripsense.live.runner import recover, run_live
from gripsense.live.sources import EpochReplay, ReplaySource, SerialSource, TcpSource, open_replay
from gripsense.live.stream_ingest import AutoIngest, LiveUbxIngest

__all__ = [
    "AutoIngest",
    "EpochReplay",
    "LiveIngest",
    "LiveUbxIngest",
    "ReplaySource",
    "SerialSource",
    "TcpSource",
    "open_replay",
    "recover",
    "run_live",
]
