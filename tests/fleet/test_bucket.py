"""``--bucket``: an interval DuckDB reads, checked before any work, or one line saying how to
write one (it was a DuckDB traceback labelled "internal error" after every log was estimated)."""

from __future__ import annotations

import pytest

from gripsense.data import path as data_path
from gripsense.errors import InputError
from gripsense.fleet.aggregate import check_bucket
from tests.cli.inprocess import cli


@pytest.mark.parametrize("bucket", ["1 hour", "15 minutes", "1 day", "90 seconds", "2 hours"])
def test_intervals_duckdb_reads_are_taken(bucket):
    assert check_bucket(bucket) == bucket


@pytest.mark.parametrize(
    ("bucket", "why"),
    [
        ("nope", "not a time interval"),
        ("", "not a time interval"),
        ("1 hour'; SELECT 1; --", "not a time interval"),  # a quote never reaches the SQL
        ("0 hours", "not a positive interval"),
        ("-1 hour", "not a positive interval"),
    ],
)
def test_other_buckets_are_one_line_naming_the_option(bucket, why):
    with pytest.raises(InputError) as e:
        check_bucket(bucket)
    line = str(e.value)
    assert "\n" not in line and line.startswith(f"--bucket {bucket!r}: {why}")
    assert "'15 minutes'" in line  # how to write one


def test_the_command_refuses_a_bad_bucket_before_any_work(tmp_path):
    log = data_path("demo/case001.nmea.gz")
    vehicle = data_path("demo/vehicle.toml")
    out = tmp_path / "fleet"
    r = cli("fleet", log, "--vehicle", vehicle, "--bucket", "nope", "-o", out)
    assert r.returncode == 2, r.stderr
    assert r.stderr.strip().splitlines() == [
        "error: --bucket 'nope': not a time interval; give a positive interval, e.g. "
        "'15 minutes', '1 hour', '1 day'"
    ]
    assert "tasks" not in r.stdout  # refused before a log was read
    assert not out.exists()
