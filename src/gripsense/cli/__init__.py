"""The ``gripsense`` command line: a thin layer over the library, one module per command group.

==============  ==============================================================================
module          commands
==============  ==============================================================================
ingest          ``ingest``
friction        ``friction``, ``report``, ``stiffness``
sensors         ``brake-mu``, ``camber``, ``camera-slip``
tyre            ``tyre eval``, ``tyre fit``, ``tyre fit-contact`` (also ``fit-contact``)
steering        ``steering identify``
sim             ``simulate``, ``demo``
live            ``live``
fleet           ``fleet``
==============  ==============================================================================
"""

from __future__ import annotations

import typer

from gripsense.cli.fleet import fleet
from gripsense.cli.friction import friction, report_cmd, stiffness
from gripsense.cli.ingest import ingest
from gripsense.cli.live import live
from gripsense.cli.sensors import brake_mu, camber, camera_slip
from gripsense.cli.sim import demo, simulate
from gripsense.cli.steering import steering_app
from gripsense.cli.tyre import fit_contact, tyre_app

__all__ = ["app", "main"]

app = typer.Typer(
    add_completion=False,
    no_args_is_help=True,
    help="gripsense: tyre-road friction, tyre and steering parameters from how a vehicle moves.",
)

app.command()(ingest)
app.command()(friction)
app.command("report")(report_cmd)
app.command()(stiffness)
app.command("brake-mu")(brake_mu)
app.command()(camber)
app.command("camera-slip")(camera_slip)
app.command("fit-contact")(fit_contact)
app.command()(simulate)
app.command()(demo)
app.command()(live)
app.command()(fleet)
tyre_app.command("fit-contact")(fit_contact)
app.add_typer(tyre_app, name="tyre")
app.add_typer(steering_app, name="steering")


def main() -> None:
    """Console-script entry point (``gripsense``)."""
    app()


if __name__ == "__main__":
    main()
