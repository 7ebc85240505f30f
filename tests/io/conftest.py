from tests.io.simulated import simulated  # noqa: F401  (real files of `gripsense simulate`)
