"""Measurements from lasers and cameras (seed 002 §2.1); OpenCV parts need the ``vision`` extra."""
