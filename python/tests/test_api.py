"""The package's calls against the command line's: the same messages, the
same numbers, the same JSON."""

from __future__ import annotations

import json
import pickle

import numpy as np
import pandas as pd
import pytest

import reldesign
from conftest import EXAMPLE, QUICK_CAUSES, ROOT, read_record, run_cli


def test_description_error_names_file_line_and_key(tmp_path, cli):
    bad = ROOT / "tests" / "data" / "bad" / "backstepping-gain-zero.toml"
    with pytest.raises(reldesign.DescriptionError) as caught:
        reldesign.Actuator.from_toml(str(bad))
    message = str(caught.value)
    assert "\x1b[" not in message, "no ANSI colour"
    assert f"{bad}:" in message or str(bad.relative_to(ROOT)) in message or bad.name in message
    assert caught.value.line > 0 and caught.value.key
    # the command line's rendering, colours aside
    run = run_cli(cli, "check", bad)
    assert run.returncode == 1
    assert run.stderr.strip() == message.strip()
    assert isinstance(caught.value, ValueError)


def test_from_str_error_and_pickle():
    text = EXAMPLE.read_text()
    valve = reldesign.Actuator.from_str(text, "valve.toml")
    assert valve.name == "semera_valve" and valve.file_name == "valve.toml"
    again = pickle.loads(pickle.dumps(valve))
    assert again.text == text and again.file_name == "valve.toml"
    with pytest.raises(reldesign.DescriptionError) as caught:
        reldesign.Actuator.from_str(text.replace("turns = 1200", "turns = -3"), "valve.toml")
    assert "valve.toml:" in str(caught.value) and caught.value.key == "coil.turns"


def test_simulate_equals_the_command_line(tmp_path, cli):
    data = ROOT / "tests" / "data" / "ja-three-pulses.csv"
    model = ROOT / "examples" / "jiles-atherton-valve.toml"
    out = tmp_path / "sim.csv"
    run = run_cli(cli, "simulate", model, "--input", data, "--out", out)
    assert run.returncode == 0, run.stderr
    expected = pd.read_csv(out)
    record = pd.read_csv(data, comment="#")
    got = reldesign.simulate(str(model), record["t"], record["v"])
    assert list(got.columns) == list(expected.columns)
    for column in expected.columns:
        np.testing.assert_array_equal(got[column].to_numpy(), expected[column].to_numpy(), column)


def test_diagnose_equals_the_command_line(records, tmp_path, cli):
    path = records / "unit-001.csv"
    out = tmp_path / "cli"
    run = run_cli(
        cli, "diagnose", EXAMPLE, path, "--json", "--out", out, "--causes", ",".join(QUICK_CAUSES)
    )
    assert run.returncode == 0, run.stderr
    expected = json.loads(run.stdout)
    valve = reldesign.Actuator.from_toml(str(EXAMPLE))
    d = reldesign.diagnose(valve, str(path), out_dir=out, causes=QUICK_CAUSES, write=False)
    assert d.to_dict() == expected
    assert d.causes == expected["causes"] and d.gain == expected["gain"]
    assert d.parameters == expected["parameters"]
    assert d.extended == (out / "unit-001.extended.toml").read_text()
    text = run_cli(
        cli, "diagnose", EXAMPLE, path, "--out", out, "--causes", ",".join(QUICK_CAUSES)
    ).stdout
    assert d.report() == text
    # a DataFrame gives the same answer as its CSV
    frame = read_record(path)
    from_frame = reldesign.diagnose(valve, frame, name=str(path), out_dir=out, causes=QUICK_CAUSES)
    assert from_frame.to_dict() == expected
    assert (out / "unit-001.report.txt").read_text() == d.report()


def test_broken_record_raises_the_record_error(records):
    with pytest.raises(reldesign.RecordError) as caught:
        reldesign.diagnose(str(EXAMPLE), str(records / "unit-broken.csv"), causes=QUICK_CAUSES)
    assert "unit-broken.csv:5:" in str(caught.value)


def test_fit_recovers_the_resistance(records):
    valve = reldesign.Actuator.from_toml(str(EXAMPLE))
    result = reldesign.fit(valve, pd.read_csv(records / "unit-000.csv"), ["coil.resistance"])
    assert result["wnrmse_current"] <= result["wnrmse_current_before"]
    assert 70 < result["values"]["coil.resistance"] < 80
    assert "resistance" in result["description"]


def test_design_equals_build_report_json(tmp_path, cli):
    model = ROOT / "examples" / "perfect-tracking-valve.toml"
    code_path, json_path = tmp_path / "valve.rs", tmp_path / "report.json"
    run = run_cli(cli, "build", model, "--quiet", "--out", code_path, "--report-json", json_path)
    assert run.returncode == 0, run.stderr
    design = reldesign.design(str(model))
    assert design.report() == json.loads(json_path.read_text())
    assert design.report_json == json_path.read_text()
    assert design.emit() == code_path.read_text()


def test_loop_and_sweep_equal_the_command_line(tmp_path, cli):
    model = ROOT / "examples" / "perfect-tracking-valve.toml"
    out = tmp_path / "loop.csv"
    run = run_cli(cli, "loop", model, "--out", out)
    assert run.returncode == 0, run.stderr
    expected = pd.read_csv(out)
    got = reldesign.loop(str(model))
    assert list(got.columns) == list(expected.columns)
    for column in expected.columns:
        np.testing.assert_array_equal(got[column].to_numpy(), expected[column].to_numpy(), column)
    for outcome in got.attrs["outcomes"]:
        assert f"{outcome['bounces']} bounce(s)" in run.stdout
        assert f"at {outcome['arrival'] * 1e3:.4f} ms" in run.stdout
        assert outcome["late"] is False and outcome["flagged_late"] is False
    run = run_cli(cli, "sweep", model, "--sample-periods", "1e-5,2e-5", "--json")
    assert run.returncode == 0, run.stderr
    expected = json.loads(run.stdout)
    table = reldesign.sweep(str(model), [1e-5, 2e-5])
    rows = table.to_dict("records")
    for row, line in zip(rows, expected["rows"]):
        assert {k: row[k] for k in line if k != "design"} == {k: v for k, v in line.items() if k != "design"}
    assert table.attrs["switching"] == expected["switching"]
