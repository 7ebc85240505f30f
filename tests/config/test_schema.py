"""One schema per configuration kind drives reading, validation, did-you-mean, the docs' key
tables and the templates: a key's plausible range, unit and default are written once."""

from __future__ import annotations

import copy
import dataclasses
import tomllib
from pathlib import Path

import pytest

from gripsense.config import Vehicle
from gripsense.config.docs import SCHEMAS, configuration_markdown
from gripsense.config.receiver import RECEIVER
from gripsense.config.vehicle_schema import (
    ANTENNA,
    CONTACT_LENGTH,
    STEERING_SYSTEM,
    TYRE,
    VEHICLE,
)
from gripsense.data import path as data_path
from gripsense.errors import InputError

DOCS = Path(__file__).resolve().parents[2] / "docs" / "configuration.md"
BASE = tomllib.loads(data_path("corolla_sim.toml").read_text(encoding="utf-8"))


def _where(table: str) -> list[str]:
    """Where a table's keys stand in BASE."""
    return {
        "vehicle": ["vehicle"],
        "antenna": ["antenna"],
        "tyre.front / tyre.rear": ["tyre", "rear"],
        "tyre.*.contact_length": ["tyre", "rear", "contact_length"],
        "receiver": ["receiver"],
        "steering": ["steering"],
    }[table]


def _with(table, key: str, value) -> dict:
    doc = copy.deepcopy(BASE)
    t = doc
    for part in _where(table.name):
        t = t.setdefault(part, {})
    if table is CONTACT_LENGTH:
        t.clear()  # a or b or fixed_m: the key under test alone (with its partner)
        t.update({"a": 0.0104, "b": -1.017e-4} if key != "fixed_m" else {})
    if table is TYRE and key == "cornering_stiffness_N_per_rad":
        t.pop("tread_stiffness_N_per_m3")
    if key == "steering_ratio":  # the ratio is given once ([steering] ratio agrees or is absent)
        doc.get("steering", {}).pop("ratio", None)
    t[key] = value
    return doc


def test_docs_are_the_schemas():
    assert DOCS.read_text(encoding="utf-8") == configuration_markdown(), (
        "docs/configuration.md is out of date: python -m gripsense.config.docs > "
        "docs/configuration.md"
    )
    for t in SCHEMAS:
        for k in t.keys:
            assert f"| `{k.name}` |" in DOCS.read_text(encoding="utf-8")


@pytest.mark.parametrize(
    "table",
    [VEHICLE, ANTENNA, TYRE, CONTACT_LENGTH, RECEIVER, STEERING_SYSTEM],
    ids=lambda t: t.name,
)
def test_every_plausible_range_is_enforced_by_the_reader(table):
    checked = 0
    for k in table.keys:
        if k.kind != "number" or k.plausible is None:
            continue
        lo, hi = k.plausible
        inside = min(max(0.5 * (lo + hi), lo), hi)
        if k.name in ("cg_height_m",):
            inside = 0.55  # the track must carry it (a rule across keys)
        if k.name in ("x_m", "y_m", "fixed_m", "width_m", "cornering_stiffness_N_per_rad"):
            inside = {"x_m": -0.8, "y_m": -0.53, "fixed_m": 0.13, "width_m": 0.185}.get(k.name, 5e4)
        for value, ok in ((inside, True), (hi + abs(hi) + 1.0, False), (lo - abs(lo) - 1.0, False)):
            doc = _with(table, k.name, value)
            if ok:
                Vehicle.from_dict(doc, source="v.toml")
                continue
            with pytest.raises(InputError, match=rf"{k.name}.*(plausible range|must be > 0)"):
                Vehicle.from_dict(doc, source="v.toml")
        checked += 1
    assert checked >= 1


@pytest.mark.parametrize(
    "table", [VEHICLE, ANTENNA, TYRE, RECEIVER, STEERING_SYSTEM], ids=lambda t: t.name
)
def test_a_misspelt_key_names_the_closest(table):
    k = next(k for k in table.keys if k.kind == "number")
    doc = _with(table, k.name[:-1] + "x", 1.0)
    with pytest.raises(InputError, match=rf"did you mean '{k.name}'"):
        Vehicle.from_dict(doc, source="v.toml")


def test_defaults_are_the_ones_the_docs_state():
    """A vehicle file without the optional keys reads as docs/friction.md says (its prose states
    the defaults, "`key` (…, N)"), for the reader, the dataclasses and the schema alike."""
    import re

    text = (DOCS.parent / "friction.md").read_text(encoding="utf-8")
    stated = {
        k: float(v) for k, v in re.findall(r"`(\w+)` \((?:[^()`]*?, )?(-?\d+(?:\.\d+)?)\)", text)
    }
    v = Vehicle.from_dict(BASE, source="v.toml")
    checked = 0
    for table, obj in ((VEHICLE, v), (TYRE, v.tyres["rear"])):
        for k in table.keys:
            if k.name in stated and k.kind == "number" and k.name not in BASE.get(table.name, {}):
                assert getattr(obj, k.name) == stated[k.name] == k.default, k.name
                checked += 1
    assert checked >= 6


def test_template_with_values_reads_back():
    values = {k: BASE["vehicle"][k] for k in VEHICLE.names if k in BASE["vehicle"]}
    text = VEHICLE.template(values) + ANTENNA.template(BASE["antenna"]) + RECEIVER.template()
    doc = tomllib.loads(text)
    doc["tyre"] = BASE["tyre"]
    v = Vehicle.from_dict(doc, source="template.toml")
    assert v.mass_kg == BASE["vehicle"]["mass_kg"] and v.roll_camber_gain == 0.8
    assert v.receiver is not None and v.receiver.heading_slow_tau_s == 20.0


def test_steering_car_file_is_read_through_its_schema(tmp_path):
    """Every number key of a steering-system file: absent → its default or a 'missing' error,
    not positive → an error naming it; the dataclass keeps the schema's defaults."""
    from gripsense.config import SteeringCar
    from gripsense.config.steering import STEERING_TABLES

    base = tomllib.loads(data_path("of18_steering.toml").read_text(encoding="utf-8"))
    f = tmp_path / "car.toml"

    def write(doc):
        lines = []
        for table, t in doc.items():
            lines.append(f"[{table}]")
            lines += [f"{k} = {v!r}" if not isinstance(v, str) else f'{k} = "{v}"'
                      for k, v in t.items()]  # fmt: skip
        f.write_text("\n".join(lines) + "\n")

    for table in STEERING_TABLES:
        for k in table.keys:
            if k.kind != "number":
                continue
            doc = copy.deepcopy(base)
            doc[table.name][k.name] = -1.0
            write(doc)
            with pytest.raises(InputError, match=rf"\[{table.name}\] {k.name}.*> 0"):
                SteeringCar.from_toml(f)
            doc[table.name].pop(k.name)
            write(doc)
            if k.required:
                with pytest.raises(InputError, match=rf"\[{table.name}\] {k.name}: missing"):
                    SteeringCar.from_toml(f)
            else:
                car = SteeringCar.from_toml(f)
                if k.default is not None:
                    assert getattr(car, k.name) == k.default


def test_scenario_defaults_are_the_emulators():
    """The scenario tables' defaults are those of the emulators they configure (their own
    signatures and dataclass, read here independently of the schema)."""
    import inspect

    from gripsense.config.scenario_schema import ACCELEROMETER, GNSS, STEERING_CHANNEL
    from gripsense.sim.gnss import CompassNoise
    from gripsense.sim.sensors import emulate_accelerometer, emulate_steering
    from gripsense.sim.steering_torque import emulate_torque

    for f in dataclasses.fields(CompassNoise):
        assert GNSS[f.name].default == f.default, f.name
    for table, fn in ((ACCELEROMETER, emulate_accelerometer), (STEERING_CHANNEL, emulate_steering)):
        sig = inspect.signature(fn).parameters
        for k in table.keys:
            if k.name.startswith(("torque", "assist")):
                continue  # the torque channel's keys: below
            assert sig[k.name].default == k.default, (table.name, k.name)
    sig = inspect.signature(emulate_torque).parameters
    for k in STEERING_CHANNEL.keys:
        if k.name.startswith("torque_") or k.name == "assist_channel":
            name = k.name.removeprefix("torque_")
            assert sig[name].default == k.default, k.name
