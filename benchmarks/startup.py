"""Start-up of the command line: wall time of ``gripsense --help``, ``--version`` and a few
``COMMAND --help`` (best of ``--repeat`` runs each, every run a fresh process), next to two
baselines measured in the same run: ``python -c pass`` (the interpreter alone) and
``python -c "import typer"`` (the command-line library alone). Prints the wall and CPU
(user + system) seconds and the wall time's ratio to each baseline; issue 45's target is
≤ 0.5 s wall for every help page on the quiet 2-core machine.

``--all`` times every command's help; ``--src DIR`` puts DIR first on ``PYTHONPATH`` (another
checkout's ``src``: the numbers before a change, e.g.
``git archive <commit> src | tar -x -C /tmp/old`` then ``--src /tmp/old/src``).

Usage: python benchmarks/startup.py [--repeat 5] [--all] [--src DIR]
"""

from __future__ import annotations

import argparse
import os
import resource
import shutil
import subprocess
import sys
import time
from pathlib import Path

EXE = shutil.which("gripsense") or str(Path(sys.executable).with_name("gripsense"))
HELP = [
    ["--help"],
    ["--version"],
    ["friction", "--help"],
    ["tyre", "eval", "--help"],
    ["steering", "identify", "--help"],
]


def best_of(cmd: list[str], repeat: int, env: dict[str, str]) -> tuple[float, float] | None:
    """Best wall time and best CPU time (user + system) of *repeat* runs of *cmd* [s]; ``None``
    when it does not exit 0 (an older checkout without ``--version``). The CPU time hardly
    depends on what else the machine runs; the wall time does.
    """
    walls, cpus = [], []
    for _ in range(repeat):
        c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        r = subprocess.run(cmd, capture_output=True, env=env, timeout=300)
        walls.append(time.perf_counter() - t0)
        c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
        cpus.append(c1.ru_utime - c0.ru_utime + c1.ru_stime - c0.ru_stime)
        if r.returncode != 0:
            return None
    return min(walls), min(cpus)


def every_help() -> list[list[str]]:
    """``--help`` of every command and sub-command (from the typer app)."""
    import typer

    from gripsense.cli import app

    out = []

    def walk(cmd, path):
        out.append([*path, "--help"])
        for name, sub in getattr(cmd, "commands", {}).items():
            walk(sub, [*path, name])

    walk(typer.main.get_command(app), [])
    return [["--version"], *out]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--all", action="store_true", help="every command's --help")
    ap.add_argument("--src", type=Path, help="another checkout's src folder, first on the path")
    args = ap.parse_args()
    env = dict(os.environ)
    if args.src is not None:
        env["PYTHONPATH"] = os.pathsep.join([str(args.src.resolve()), env.get("PYTHONPATH", "")])
    py = sys.executable
    print(f"best of {args.repeat} runs, {os.cpu_count()} CPUs, load {os.getloadavg()[0]:.2f}")
    print(f"{'command':<40} {'wall':>8} {'CPU':>8}", end="")
    print(f"  {'÷ python -c pass':>16}  {'÷ import typer':>14}")
    base: list[float] = []
    worst = 0.0
    runs = [[py, "-c", "pass"], [py, "-c", "import typer"]]
    runs += [[py, EXE, *argv] for argv in (every_help() if args.all else HELP)]
    for cmd in runs:
        name = "python " + " ".join(cmd[1:]) if len(base) < 2 else "gripsense " + " ".join(cmd[2:])
        t = best_of(cmd, args.repeat, env)
        if t is None:
            if len(base) < 2:
                raise SystemExit(f"{name}: fails")
            print(f"{name:<40} fails")
            continue
        wall, cpu = t
        if len(base) < 2:
            base.append(wall)
            print(f"{name:<40} {wall:6.3f} s {cpu:6.3f} s")
            continue
        worst = max(worst, wall)
        ratios = f"{wall / base[0]:15.1f}×  {wall / base[1]:13.1f}×"
        print(f"{name:<40} {wall:6.3f} s {cpu:6.3f} s  {ratios}")
    print(f"slowest: {worst:.3f} s wall (target ≤ 0.5 s on the quiet 2-core machine)")


if __name__ == "__main__":
    main()
