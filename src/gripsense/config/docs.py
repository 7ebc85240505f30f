"""The configuration keys as documentation: ``docs/configuration.md`` is this module's output
(``python -m gripsense.config.docs > docs/configuration.md``; a test keeps them equal).
"""

from __future__ import annotations

from gripsense.config.receiver import RECEIVER
from gripsense.config.scenario_schema import SCENARIO_TABLES
from gripsense.config.steering import STEERING_TABLES
from gripsense.config.vehicle_schema import (
    ANTENNA,
    CALIBRATION,
    CONTACT_LENGTH,
    STEERING_SYSTEM,
    TYRE,
    VEHICLE,
)

__all__ = ["SCHEMAS", "configuration_markdown"]

SCHEMAS = (
    VEHICLE,
    ANTENNA,
    TYRE,
    CONTACT_LENGTH,
    STEERING_SYSTEM,
    CALIBRATION,
    RECEIVER,
    *STEERING_TABLES,
    *SCENARIO_TABLES,
)
"""Every table of a vehicle file (``[receiver]`` may also stand in a file of its own), then the
tables of a steering-system file (``gripsense steering identify``) and of a scenario file
(``gripsense simulate``)."""

_HEAD = """# Configuration keys

Every key of the vehicle file, of a receiver file, of a steering-system file (`[car]`,
`[steering]`, `[tyre]`, `[test]`; `gripsense steering identify`) and of a scenario file
(`[scenario]`, `[road]`, `[gnss]`, `[accelerometer]`, `[steering]`; `gripsense simulate`; the
manoeuvres' keys are in `gripsense.sim.scenario`), with its unit, default and plausible range
(a value outside is an error naming the range: most often a unit mistake). Unknown keys are
errors that suggest the closest known key. Generated from the schemas in
`gripsense.config.vehicle_schema`, `gripsense.config.receiver`, `gripsense.config.steering` and
`gripsense.config.scenario_schema` — the same entries the readers check — by
`python -m gripsense.config.docs`; rules that tie keys together (a weight share or a CG
position, both roll-centre heights or neither, the track against the CG height) are stated in
the meaning column and checked by `Vehicle.from_dict`.
"""


def configuration_markdown() -> str:
    """``docs/configuration.md``: the key tables and a template of each table.

    Returns
    -------
    str
        The Markdown text.
    """
    parts = [_HEAD]
    for t in SCHEMAS:
        parts.append("## " + t.markdown())
    parts.append(
        "## Templates\n\nRequired keys first, optional ones commented out at their default:\n"
    )
    parts.append(
        "```toml\n" + "\n".join(t.template() for t in (VEHICLE, ANTENNA, RECEIVER)) + "```\n"
    )
    return "\n".join(parts)


if __name__ == "__main__":
    print(configuration_markdown(), end="")
