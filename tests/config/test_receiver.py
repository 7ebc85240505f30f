"""Which receiver's data are better: a partial order on the noise components the estimators use
(docs/physics.md §15.11)."""

from __future__ import annotations

import dataclasses

from hypothesis import given
from hypothesis import strategies as st

from gripsense.config.receiver import RECEIVERS, Receiver

COMPONENTS = ("heading_white_deg", "heading_slow_deg", "velocity_mps", "yaw_rate_dps")
noise = st.floats(0.0, 2.0, allow_nan=False)


def _receiver(white, slow, vel, yaw) -> Receiver:
    return Receiver("r", white, slow, vel, yaw)


def test_the_named_receivers_are_ordered_where_every_component_is():
    v100, white, rtk = RECEIVERS["v100"], RECEIVERS["white-0.3"], RECEIVERS["rtk"]
    assert white.at_least_as_good_as(v100) and rtk.at_least_as_good_as(v100)
    assert not v100.at_least_as_good_as(white) and not v100.at_least_as_good_as(rtk)
    # rtk's white noise is smaller, its slow heading error larger: neither is better data
    assert not rtk.at_least_as_good_as(white) and not white.at_least_as_good_as(rtk)


@given(st.tuples(noise, noise, noise, noise), st.tuples(noise, noise, noise, noise))
def test_better_means_no_component_larger(a, b):
    ra, rb = _receiver(*a), _receiver(*b)
    assert ra.at_least_as_good_as(ra)
    assert ra.at_least_as_good_as(rb) == all(x <= y for x, y in zip(a, b, strict=True))
    if ra.at_least_as_good_as(rb) and rb.at_least_as_good_as(ra):
        assert a == b


@given(st.tuples(noise, noise, noise, noise), st.sampled_from(COMPONENTS), st.floats(1e-3, 1.0))
def test_more_noise_in_one_component_is_never_better(a, field, extra):
    r = _receiver(*a)
    worse = dataclasses.replace(r, **{field: getattr(r, field) + extra})
    assert r.at_least_as_good_as(worse) and not worse.at_least_as_good_as(r)


def test_slow_errors_of_different_correlation_times_are_not_ordered():
    a = Receiver("a", 0.1, 0.1, 0.05, 0.1, heading_slow_tau_s=20.0)
    b = dataclasses.replace(a, heading_slow_tau_s=60.0)
    assert not a.at_least_as_good_as(b) and not b.at_least_as_good_as(a)
    # without a slow error the correlation time does not matter
    c, d = (
        dataclasses.replace(a, heading_slow_deg=0.0),
        dataclasses.replace(b, heading_slow_deg=0.0),
    )
    assert c.at_least_as_good_as(d) and d.at_least_as_good_as(c)
