"""The batch path of studies (rockdem.batch): the same rows as single runs, models from templates."""

from __future__ import annotations

import numpy as np
import pytest

from rockdem.batch import batch_row, frames_from_dataset, run_batch, summary_row
from rockdem.case import CaseTemplate, apply_overrides, example_case, load_case, parse_case, template_key
from rockdem.studies import MAX_TASK_RUNS, TIMING_COLUMNS, RunSpec, _tasks, run_spec

SMALL = {"run.record_interval": 0.01, "specimen.height": 0.5, "specimen.width": 0.19}


def _strip(row):
    return {k: v for k, v in row.items() if k not in TIMING_COLUMNS}


@pytest.fixture(scope="module")
def base():
    return example_case("free-rocking")


def _specs(base, tmp_path):
    bad = tmp_path / "broken.csv"
    bad.write_text("0.0,0.1\n0.005,0.12E-\n")
    eq = {"run.record_interval": 0.01, "run.stop": "decided"}
    specs = [RunSpec.make(base, eq, duration=5.0, record=r, pga_g=p) for r in ("elcentro-peknold", "elcentro-rsn6") for p in (0.1, 0.3, 0.7)]
    specs.append(RunSpec.make(base, {**eq, "loading.units": "g"}, duration=2.0, record=str(bad), pga_g=0.3))  # an error row
    specs.append(RunSpec.make(base, {**eq, "run.settle": True}, duration=3.0, record="elcentro-rsn6", pga_g=0.3))  # from settled blocks
    specs += [RunSpec.make(base, {**SMALL, "damping.beta": b}, duration=1.5, history=True, history_interval=0.02) for b in (0.001, 0.003)]
    specs += [RunSpec.make(base, {**SMALL, "run.stop": "rest", "damping.beta": 0.0, "damping.alpha": a}, duration=3.0, history=True)
              for a in (4.0, 8.0)]
    return specs


def test_batch_rows_are_the_single_run_rows(base, tmp_path):
    """The same specs through run_spec (parse, run, Dataset, summary) and the batch path (models
    derived from templates, raw frames), in two orders (a template built by another spec first):
    identical rows, timings aside: earthquakes stopped on collapse, free rocking with histories,
    a run stopped at rest (its history continued at rest), and an unreadable record."""
    specs = _specs(base, tmp_path)
    single = [_strip(run_spec(s)) if "broken" not in str(s.record) else None for s in specs]
    forward = [_strip(r) for r in run_batch(specs)]
    backward = [_strip(r) for r in run_batch(specs[::-1])][::-1]
    for s, a, b, c in zip(specs, single, forward, backward):
        assert b == c
        if a is None:
            assert b["status"] == "error" and "broken.csv" in b["error"]
        else:
            assert a == b
    reasons = {r.get("stop_reason") for r in forward}
    assert {"overturned", "rest", None} <= reasons  # the cases meant to be covered are
    rest = next(r for r in forward if r.get("stop_reason") == "rest")
    h = rest["history"]
    assert h["time"][-1] == pytest.approx(3.0, abs=0.011) and h["rotation"][-1] == h["rotation"][-2]  # continued at rest


def test_derived_models_are_the_parsed_models(base):
    """A template derived for another record, PGA, mode settings and damping gives parse_case's model
    array for array; another specimen is refused."""
    foundation = load_case("examples/elcentro_block_foundation.toml")
    for data in (foundation, RunSpec.make(base, SMALL, record="elcentro-rsn6", pga_g=0.2).case_dict()):
        tpl = CaseTemplate(data)
        other = apply_overrides(data, ['loading.record="elcentro-peknold"', "damping.beta=0.003", "damping.alpha=0.5",
                                       "run.duration=3.0", "loading.tail=1.5"])
        derived, parsed = tpl.derive(other), parse_case(other)
        for name, a, b in zip(parsed.model.arrays._fields, derived.model.arrays, parsed.model.arrays):
            assert np.array_equal(a, b), name
        assert derived.model.damping == parsed.model.damping and derived.run == parsed.run
        assert derived.attrs == parsed.attrs and derived.monitors.keys() == parsed.monitors.keys()
        for k in parsed.series:
            np.testing.assert_array_equal(derived.series[k][1], parsed.series[k][1])
        with pytest.raises(ValueError, match="specimen or loading differs"):
            tpl.derive(apply_overrides(data, ["specimen.height=1.5"]))
    # the loading is validated as parse_case validates it
    tpl = CaseTemplate(foundation)
    with pytest.raises(ValueError, match=r"\[loading\] unknown key"):
        tpl.derive(apply_overrides(foundation, ["loading.scael=2.0"]))


def test_rockdem_run_result_gives_the_batch_row(base, tmp_path):
    """``rockdem run --stop decided`` (NetCDF written and read back) and the batch path: one row.
    A block released past eta is stopped as overturned."""
    from rockdem.cli import main
    from rockdem.results import load

    over = {**SMALL, "damping.beta": 0.0, "damping.alpha": 2.0, "loading.tilt_fraction": 1.02, "run.stop": "decided",
            "run.duration": 2.0}
    spec = RunSpec.make(base, over)
    assert main(["run", "--example", "free-rocking", "--out", str(tmp_path), "--no-plot", "--quiet", "--stop", "decided",
                 *(a for k, v in over.items() if k != "run.stop" for a in ("--set", f"{k}={v}"))]) == 0
    ds = load(tmp_path / "result.nc")
    assert ds.attrs["stop_reason"] == "overturned"
    from_file = summary_row(spec, spec.case_dict(), frames_from_dataset(ds))
    assert _strip(from_file) == _strip(batch_row(spec))


def test_tasks_keep_a_specimen_together(base):
    """Pool tasks group runs by specimen (one model per worker) and stay small enough to balance."""
    ida = [RunSpec.make(base, SMALL, record=r, pga_g=p) for r in ("elcentro-rsn6", "elcentro-peknold") for p in np.linspace(0.1, 1, 40)]
    other = [RunSpec.make(base, {**SMALL, "specimen.height": 0.6}, pga_g=p, record="elcentro-rsn6") for p in (0.2, 0.4)]
    tasks = _tasks(other[:1] + ida + other[1:], 2, batch=True)
    assert sorted(s.id for t in tasks for s in t) == sorted(s.id for s in other + ida)
    for t in tasks:
        assert len({template_key(s.case_dict()) for s in t}) == 1 and len(t) <= MAX_TASK_RUNS
    assert len(tasks) >= 2 * 4  # at least TASKS_PER_WORKER tasks per worker
    assert [len(t) for t in _tasks(ida, 2, batch=False)] == [1] * len(ida)


def test_start_is_copied_not_shared(base):
    """The cached start of a specimen is copied for each run, field by field."""
    from rockdem.simulation import prepare_start

    case = parse_case(apply_overrides(base, [f"{k}={v}" for k, v in SMALL.items()]))
    start = prepare_start(case.model)
    copy = start.copy()
    assert copy.timestep == start.timestep
    for a, b in zip(copy.state + copy.scratch, start.state + start.scratch):
        assert a is not b and np.array_equal(a, b)


AUTO = {"damping.beta": "auto", "damping.target_restitution": "eta", "damping.probe_impacts": 2, "damping.release_fraction": 0.5}


def _choice_attrs(model):
    return {k: v.tolist() if isinstance(v, np.ndarray) else v
            for k, v in model.beta_choice.attrs().items() if k not in ("beta_search_time_s", "beta_how")}


def test_derived_models_with_an_automatic_beta_are_the_parsed_models(base):
    """beta = "critical" / "auto" derived from a template of another damping (and back to a number):
    parse_case's arrays, damping and beta choice; the numeric one keeps no choice of the template's."""
    data = RunSpec.make(base, SMALL, record="elcentro-rsn6", pga_g=0.2).case_dict()
    tpl = CaseTemplate(data)
    for over in ({"damping.beta": "critical"}, AUTO, {"damping.beta": 0.002}):
        other = apply_overrides(data, [f"{k}={v!r}" if isinstance(v, str) else f"{k}={v}" for k, v in over.items()]
                                + ['loading.record="elcentro-peknold"'])
        derived, parsed = tpl.derive(other), parse_case(other)
        for name, a, b in zip(parsed.model.arrays._fields, derived.model.arrays, parsed.model.arrays):
            assert np.array_equal(a, b), name
        assert derived.model.damping == parsed.model.damping
        if parsed.model.beta_choice is None:
            assert derived.model.beta_choice is None and over["damping.beta"] == 0.002
        else:
            assert _choice_attrs(derived.model) == _choice_attrs(parsed.model)
            assert derived.model.damping.beta == parsed.model.beta_choice.beta > 0


def test_automatic_beta_sweep_rows_by_both_paths(base, monkeypatch):
    """A sweep over records and PGAs with beta = "critical", a number and beta = "auto", interleaved
    on one specimen: the batch path resolves each automatic beta once (not per run) and gives the
    single runs' rows, the chosen beta and its search record included."""
    from collections import OrderedDict

    from rockdem import batch, targeting
    from rockdem.beta_choice import housner_e_eta

    calls = []
    choose = targeting.choose_beta
    monkeypatch.setattr(targeting, "choose_beta", lambda *a, **k: calls.append(1) or choose(*a, **k))
    monkeypatch.setattr(batch, "_TEMPLATES", OrderedDict())
    monkeypatch.setattr(batch, "_STARTS", OrderedDict())
    eq = {**SMALL, "run.stop": "decided"}
    dampings = ({"damping.beta": "critical"}, {"damping.beta": 0.0005}, AUTO)
    specs = [RunSpec.make(base, {**eq, **d}, duration=1.5, record=r, pga_g=p)
             for r in ("elcentro-rsn6", "elcentro-peknold") for p in (0.5, 1.0) for d in dampings]
    rows = run_batch(specs)
    assert len(calls) == 2  # one critical, one targeted resolution for 12 runs
    single = [run_spec(s) for s in specs]
    assert len(calls) == 2 + 8  # a single run resolves its own
    for s, a, b in zip(specs, single, rows):
        assert b["status"] == "ok" and _strip(a) == _strip(b), s.inputs
    by = {d["damping.beta"]: [r for r in rows if r["damping.beta"] == d["damping.beta"]] for d in dampings}
    assert "beta_s" not in by[0.0005][0]
    crit, auto = by["critical"], by["auto"]
    assert len({r["beta_s"] for r in crit}) == 1 and "block-foundation" in crit[0]["beta_pairs"] and "(critical)" in crit[0]["beta_pairs"]
    assert len({(r["beta_s"], r["beta_search_time_s"]) for r in auto}) == 1  # one search, its record on every row
    assert auto[0]["beta_target_value"] == pytest.approx(housner_e_eta(np.arctan2(0.19, 0.5)))
    assert abs(auto[0]["beta_achieved_e_a"] / auto[0]["beta_target_value"] - 1) < 0.01
    # the chosen beta is the one run: its responses differ from beta = 0.0005's on the same inputs
    # (implicit dashpots: the step no longer depends on beta, so the step counts may agree)
    assert [r["max_rotation_rad"] for r in crit] != [r["max_rotation_rad"] for r in by[0.0005]]
