"""Measurements from lasers and cameras (seed 002 §2.1); OpenCV parts need the ``vision`` extra
(imported only when a camera function runs).
"""

from gripsense.vision.camber_laser import calibration_offsets, camber_from_lasers
from gripsense.vision.slip_camera import frame_pair_flow, slip_from_frames

__all__ = ["calibration_offsets", "camber_from_lasers", "frame_pair_flow", "slip_from_frames"]
