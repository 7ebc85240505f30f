"""Every command's output path: existing as a user's file, a user's folder, unwritable, or with
missing parents. The command either succeeds or fails with one line on stderr and a non-zero
exit — and no file the user made is changed or deleted (checked by content hash)."""

from __future__ import annotations

import hashlib
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from gripsense.cli import main
from gripsense.data import sample_path
from gripsense.demo import demo_dir
from tests.conftest import DATA

DEMO = demo_dir()
VEH = DEMO / "vehicle.toml"
LOG = DEMO / "case022.nmea.gz"
UNWRITABLE = Path("/proc/gripsense-unwritable")  # not writable even for root


def run_cli(args, capsys) -> tuple[int, str, str]:
    """Run ``gripsense ARGS`` in-process through the console-script entry point."""
    old = sys.argv
    sys.argv = ["gripsense", *map(str, args)]
    try:
        main()
        code = 0
    except SystemExit as e:
        code = int(e.code or 0)
    finally:
        sys.argv = old
    out, err = capsys.readouterr()
    return code, out, err


@pytest.fixture(scope="module")
def inputs(tmp_path_factory):
    d = tmp_path_factory.mktemp("inputs")
    t = np.arange(0, 6, 0.02)
    ax = np.where((t > 2) & (t < 4.5), -0.8, 0.0) + 0.03 * np.random.default_rng(0).normal(
        size=t.size
    )
    pd.DataFrame({"t_s": t, "ax_g": ax, "ay_g": 0.0, "az_g": 1.0}).to_csv(
        d / "acc.csv", index=False
    )
    pd.DataFrame({"t_s": t, "d_outer_mm": 100.0, "d_inner_mm": 100.0}).to_csv(
        d / "laser.csv", index=False
    )
    from gripsense.physics.magic_formula.pac94 import pac94_lateral
    from gripsense.sim.tyre_data import PAC94_EXAMPLE, rig_samples

    rig_samples(
        lambda fz, a, g: pac94_lateral(PAC94_EXAMPLE, fz, a, g), 400, rng=np.random.default_rng(1)
    ).to_csv(d / "tyre.csv", index=False)
    (d / "scen.toml").write_text(
        '[scenario]\nvehicle = "corolla_sim.toml"\n[[case]]\nmaneuver = "fixed_steer"\n'
        "speed_kmh = 20\nsteer_deg = 2\nduration_s = 4\n"
    )
    res = d / "result"
    code = main_ok(["friction", LOG, "--vehicle", VEH, "-o", res])
    assert code == 0
    return {
        "acc": d / "acc.csv",
        "laser": d / "laser.csv",
        "tyre": d / "tyre.csv",
        "scen": d / "scen.toml",
        "result": res,
    }


def main_ok(args) -> int:
    old = sys.argv
    sys.argv = ["gripsense", *map(str, args)]
    try:
        main()
        return 0
    except SystemExit as e:
        return int(e.code or 0)
    finally:
        sys.argv = old


# command → (arguments with OUT for the output, the output is a "file" or a "folder")
COMMANDS = {
    "ingest": (lambda i: ["ingest", LOG, "-o", "OUT.parquet"], "file"),
    "friction": (lambda i: ["friction", LOG, "--vehicle", VEH, "-o", "OUT"], "folder"),
    "report": (lambda i: ["report", i["result"], "-o", "OUT.html"], "file"),
    "stiffness": (
        lambda i: ["stiffness", DEMO / "case001.nmea.gz", "--vehicle", VEH, "-o", "OUT"],
        "folder",
    ),
    "brake-mu": (lambda i: ["brake-mu", i["acc"], "-o", "OUT.csv"], "file"),
    "camber": (lambda i: ["camber", i["laser"], "--spacing-m", "0.2", "-o", "OUT.csv"], "file"),
    "tyre-eval": (
        lambda i: [
            "tyre",
            "eval",
            DATA / "tyre" / "tir" / "FSAE_Defaults.tir",
            "--fz",
            "1000",
            "-o",
            "OUT.csv",
        ],
        "file",
    ),
    "tyre-fit": (lambda i: ["tyre", "fit", i["tyre"], "-o", "OUT.json"], "file"),
    "steering": (
        lambda i: [
            "steering",
            "identify",
            sample_path("of18_steering.toml"),
            "--settling",
            "0.80,0.86,0.76",
            "-o",
            "OUT",
        ],
        "folder",
    ),
    "simulate": (lambda i: ["simulate", i["scen"], "-o", "OUT"], "folder"),
    "live": (
        lambda i: [
            "live",
            "--replay",
            DEMO / "case001.nmea.gz",
            "--speed",
            "0",
            "--vehicle",
            VEH,
            "--quiet",
            "-o",
            "OUT.csv",
        ],
        "file",
    ),
}


def _args(name, inputs, out: Path):
    make, _ = COMMANDS[name]
    args = []
    for a in make(inputs):
        s = str(a)
        args.append(str(out) + s[3:] if s.startswith("OUT") else s)
    return args


def _snapshot(root: Path) -> dict[str, str]:
    return {
        str(p.relative_to(root)): hashlib.sha256(p.read_bytes()).hexdigest()
        for p in sorted(root.rglob("*"))
        if p.is_file()
    }


def _one_line_error(code: int, err: str) -> None:
    assert code != 0
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and lines[0].startswith("error:"), err
    assert "Traceback" not in err


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_output_exists_as_a_users_file(name, inputs, tmp_path, capsys):
    kind = COMMANDS[name][1]
    out = tmp_path / "out"
    target = out if kind == "folder" else Path(_args(name, inputs, out)[-1])
    target.write_text("my own notes\n")
    before = _snapshot(tmp_path)
    code, _, err = run_cli(_args(name, inputs, out), capsys)
    _one_line_error(code, err)
    assert _snapshot(tmp_path) == before
    # and with --overwrite: still refused, it is not gripsense's file
    code, _, err = run_cli([*_args(name, inputs, out), "--overwrite"], capsys)
    _one_line_error(code, err)
    assert _snapshot(tmp_path) == before


@pytest.mark.parametrize("name", [n for n in sorted(COMMANDS) if COMMANDS[n][1] == "folder"])
def test_output_is_a_users_folder(name, inputs, tmp_path, capsys):
    out = tmp_path / "out"
    (out / "epochs" / "2024").mkdir(parents=True)
    (out / "epochs" / "2024" / "notes.txt").write_text("keep me\n")
    (out / "manifest.json").write_text('{"mine": true}\n')
    before = _snapshot(tmp_path)
    for extra in ([], ["--overwrite"]):
        code, _, err = run_cli([*_args(name, inputs, out), *extra], capsys)
        _one_line_error(code, err)
        assert _snapshot(tmp_path) == before


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_unwritable_output(name, inputs, capsys):
    code, _, err = run_cli(_args(name, inputs, UNWRITABLE / "sub" / "out"), capsys)
    _one_line_error(code, err)


@pytest.mark.parametrize("name", sorted(COMMANDS))
def test_missing_parent_folders_are_created_and_a_rerun_needs_overwrite(
    name, inputs, tmp_path, capsys
):
    out = tmp_path / "a" / "b" / "out"
    args = _args(name, inputs, out)
    code, _, err = run_cli(args, capsys)
    assert code == 0, err
    written = _snapshot(tmp_path)
    assert written
    code, _, err = run_cli(args, capsys)  # the same command again: refused, nothing changed
    _one_line_error(code, err)
    assert "--overwrite" in err
    assert _snapshot(tmp_path) == written
    code, _, err = run_cli([*args, "--overwrite"], capsys)  # its own output: replaced
    assert code == 0, err


@settings(
    max_examples=12, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture]
)
@given(
    steps=st.lists(
        st.tuples(
            st.sampled_from(sorted(COMMANDS)),
            st.sampled_from(["notes", "out", "data/out", "notes/x"]),
            st.booleans(),
        ),
        min_size=1,
        max_size=4,
    )
)
def test_no_command_changes_a_file_it_did_not_create(steps, inputs, tmp_path_factory, capsys):
    """Any sequence of commands, outputs colliding with the user's files and with each other,
    with or without --overwrite: the user's files stay as they were."""
    root = tmp_path_factory.mktemp("user")
    (root / "notes").write_text("mine\n")
    (root / "data").mkdir()
    (root / "data" / "out").write_text("also mine\n")
    (root / "data" / "keep.csv").write_text("a,b\n1,2\n")
    mine = _snapshot(root)
    for name, where, overwrite in steps:
        args = _args(name, inputs, root / where)
        code, _, err = run_cli([*args, "--overwrite"] if overwrite else args, capsys)
        if code:
            _one_line_error(code, err)
        now = _snapshot(root)
        assert {k: now.get(k) for k in mine} == mine
