"""Sensor tables read beside a log: steering (:mod:`~.steer`), accelerometer (:mod:`~.accel`),
laser distance (:mod:`~.laser`) and motion tables of GNSS/INS exports (:mod:`~.motion`); all
map their columns with the one convention of :mod:`gripsense.io.table`.
"""
