"""Pure, vectorised physics: SI units in and out, every function cites its equation."""
