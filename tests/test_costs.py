"""Every command estimates its cost before it works and refuses above a minute without
--allow-slow; `choose` decides by the recorded cost model, never by this run's timings.

(The estimates against measured wall time are a benchmark, benchmarks/command_costs.py, not a
timed test.)
"""

from __future__ import annotations

import argparse
import dataclasses

import numpy as np
import pytest
from commands import run_forked


def run(*args, cwd=None):
    return run_forked(*args, check=False, cwd=cwd)


def commands() -> dict[str, argparse.ArgumentParser]:
    from lindstedt.cli import build_parser

    return build_parser()._subparsers._group_actions[0].choices


def test_every_command_but_the_demo_has_an_estimate_and_the_slow_ones_a_switch():
    from lindstedt.costs import COSTS

    names = set(commands())
    assert set(COSTS) == names - {"demo"}
    scalable = {"series", "generate", "driven", "response", "choose", "sweep", "mathieu",
                "tongues", "nnm", "ssm"}
    for name, sub in commands().items():
        has = any("--allow-slow" in a.option_strings for a in sub._actions)
        assert has == (name in scalable), name


@pytest.mark.parametrize("args,needle", [
    (["driven", "--eps", "0.1", "--force", "0.3", "--omega", "1.3", "--order", "200"],
     "order 200: about"),
    (["response", "--eps", "0.1", "--force", "1", "--Q", "50", "--harmonics", "100"],
     "--harmonics 100: about"),
    # a user's equation far below its ω0: every point's multipliers take 512·2^⌈log2(ω0/ω)⌉
    # samples a period (analysis.attractors.dynamics_seconds), the continuation alone ~3 s
    (["response", "x'' + 0.05*x' + x + x**2 = f*cos(w*t)", "--param", "f=3/10", "--omega",
      "0.005:2.2"], "--harmonics 8, --param f=3/10: about"),
    (["sweep", "stability", "--omega", "0.5:1.5:40000", "--force", "0.3", "--eps", "0.1",
      "--Q", "20", "--out", "map.zarr"], "a grid of 40,000 points: about"),
    (["generate", "q'' + q + eps*(alpha*q**2 + q**3) = 0", "--order", "100", "--out", "gen"],
     "order 100: about"),
    # a limit cycle's evaluators: the series to ≥ 60 and the shooting checks, growing with K
    (["generate", "vdp", "--order", "120", "--out", "gen"],
     "generating the limit cycle's evaluators"),
])
def test_a_long_command_is_refused_at_once_and_writes_nothing(tmp_path, args, needle):
    out = run(*args, cwd=tmp_path)
    assert out.returncode == 2, out.stderr
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and needle in lines[0] and "--allow-slow" in lines[0], lines
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("args", [["series", "duffing", "--order", "1" + "0" * 28],
                                  ["nnm", "x1'' + 2*x1 - x2 + x1**3 = 0; x2'' + 2*x2 - x1 = 0",
                                   "--order", "10000"]])
def test_an_estimate_past_a_week_is_refused_even_with_allow_slow(tmp_path, args):
    """--allow-slow runs a long command, not an endless one: past a week's estimate (a
    29-digit order: 1e90 s) the refusal stands with the switch and no longer offers it."""
    for switch in ((), ("--allow-slow",)):
        out = run(*args, *switch, cwd=tmp_path)
        lines = out.stderr.strip().splitlines()
        assert out.returncode == 2 and len(lines) == 1, (switch, out.stderr)
        assert "past the week that --allow-slow admits" in lines[0], lines
        assert "pass --allow-slow" not in lines[0]
    assert list(tmp_path.iterdir()) == []


def test_the_estimates_grow_with_the_work_and_bounds_come_first():
    """Orders the printer cannot print are refused whatever --allow-slow says; the driven
    estimate follows its fit (16 s measured at order 100, 57 s at 150)."""
    from lindstedt import costs
    from lindstedt.cli import build_parser
    from lindstedt.errors import InputError

    def parsed(*argv):
        return build_parser().parse_args(list(argv))

    est = [costs.COSTS["driven"](parsed("driven", "--eps", "0.1", "--force", "0.3", "--omega",
                                         "1.3", "--order", str(k))).seconds
           for k in (4, 100, 150, 200)]
    assert est[0] < 5 and 10 < est[1] < 25 and 40 < est[2] < 80 and est[3] > 60
    with pytest.raises(InputError, match="stops at order 130"):
        costs.COSTS["generate"](parsed("generate", "duffing", "--order", "131", "--allow-slow"))
    with pytest.raises(InputError, match="up to order 6"):
        costs.COSTS["generate"](parsed("generate", "driven", "--order", "7"))


def test_choose_driven_decides_by_the_model_not_the_timings(monkeypatch):
    """The same choice when this run's measured costs are reversed in order."""
    from lindstedt import choose

    plain = choose.choose_driven("amplitudes", 1e-6, 0.1, 0.3, 20.0, 1.3)
    real = choose.driven_tradeoffs

    def reversed_timings(*args):
        out = real(*args)  # the same records in the same order, the costs' ranks reversed
        ns = sorted((t.ns_per_point for t in out), reverse=True)
        flipped = list(out)
        for k, i in enumerate(np.argsort([t.ns_per_point for t in out])):
            flipped[i] = dataclasses.replace(out[i], ns_per_point=ns[k])
        return flipped

    monkeypatch.setattr(choose, "driven_tradeoffs", reversed_timings)
    flipped = choose.choose_driven("amplitudes", 1e-6, 0.1, 0.3, 20.0, 1.3)
    assert (flipped.method, flipped.order) == (plain.method, plain.order)
    assert flipped.modelled_ns_per_point == plain.modelled_ns_per_point
    assert plain.modelled_ns_per_point == choose.modelled_ns("driven", plain.method, plain.order)


def test_choose_emit_generates_the_modelled_cheapest_first_and_only_what_it_needs(monkeypatch):
    """With --out the emitted modules are tried cheapest-by-model first; the first whose own
    error meets the tolerance is chosen, the rest are never generated; the bounds keep out
    what would take over a minute to generate."""
    from lindstedt import choose

    tried = []

    def fake_emitted(method, order, truth, eps, force, Q):
        tried.append((method, order))
        errors = {k: np.full(truth.omega.size, 1e-12 if method == "harmonic_balance" else 1.0)
                  for k in choose.DRIVEN_QUANTITIES}
        return choose.DrivenTradeoff(f"{method}, emitted", order, 123.0, errors)

    monkeypatch.setattr(choose, "emitted_driven", fake_emitted)
    c = choose.choose_driven("amplitudes", 1e-6, 0.1, 0.3, np.inf, 1.3, emit=(4, 8))
    model = {m: choose.modelled_ns("driven", f"{m}, emitted", o) for m, o in tried}
    assert c.method == "harmonic_balance" and c.ns_per_point == 123.0
    assert tried[-1][0] == "harmonic_balance"
    assert all(model[m] <= model["harmonic_balance"] for m, _ in tried)  # cheaper ones first
    assert all(o <= (4 if m == "mu_expansion" else 8) for m, o in tried)


def test_emit_bounds_keep_choose_emit_within_the_limit():
    """What competes in ``choose … --out`` is the most whose trial fits the limit after the
    choice's fixed work (one more would not); the command's estimate stays within the limit."""
    from lindstedt import choose, costs
    from lindstedt.cli import build_parser

    assert costs.EMIT_MAX_HARMONICS == choose.DRIVEN_MAX
    budget = costs.COST_LIMIT_SECONDS - costs.FIXED_COSTS["choose amplitudes"]
    mu, n = costs.emit_bounds(False)
    for model, k in (("driven", mu), ("balance", n)):
        assert costs.emission_seconds(model, k) <= budget < costs.emission_seconds(model, k + 1)
    assert costs.emit_bounds(True) == (costs.DRIVEN_MAX_ORDER, choose.DRIVEN_MAX)
    argv = ["choose", "amplitudes", "--eps", "0.1", "--force", "0.3", "--omega", "1.3",
            "--out", "e"]
    cost = costs.COSTS["choose"](build_parser().parse_args(argv))
    assert costs.FIXED_COSTS["choose amplitudes"] < cost.seconds <= costs.COST_LIMIT_SECONDS
    slow = costs.COSTS["choose"](build_parser().parse_args([*argv, "--allow-slow"]))
    assert slow.seconds > costs.COST_LIMIT_SECONDS


def test_a_users_equation_is_estimated_by_its_degree_and_symbols():
    """A high-degree force is dearer than Duffing at the same order, symbolic coefficients
    dearer than numbers; `eps*q**63` to order 40 (4.4 minutes measured) is refused at once."""
    from lindstedt.costs import series_cost

    def cost(text, order, *pairs):
        return series_cost(argparse.Namespace(model=text, order=order,
                                              param=list(pairs) or None)).seconds

    duffing = cost("q'' + q + eps*q**3 = 0", 60)
    assert cost("q'' + q + eps*q**9 = 0", 60) > 2 * duffing
    assert cost("q'' + q + eps*(alpha*q**2 + q**3) = 0", 30) > cost(
        "q'' + q + eps*(alpha*q**2 + q**3) = 0", 30, "alpha=1/3")
    done = run("series", "q'' + q + eps*q**63 = 0", "--order", "40")
    assert done.returncode == 2 and "--allow-slow" in done.stderr and done.stdout == ""


def test_the_cost_fit_measures_every_entry_of_the_cost_model(monkeypatch):
    """``benchmarks/cost_model.py --fit`` measures every entry of ``choose.COST_MODEL`` (the
    damped μ-expansion's emitted module was missed, its line fitted by hand), and ``--only``
    just the one it names: the timings replaced by stubs that record what they are asked."""
    import importlib.util
    from pathlib import Path
    from types import SimpleNamespace

    from lindstedt.analysis.driven import Drive
    from lindstedt.choose import COST_MODEL, DrivenTradeoff
    from lindstedt.methods.registry import methods_for

    path = Path(__file__).resolve().parent.parent / "benchmarks" / "cost_model.py"
    spec = importlib.util.spec_from_file_location("cost_model", path)
    fit = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fit)

    def tradeoffs(truth, eps, force, Q):
        return [DrivenTradeoff(m.name, k, 1.0, {})
                for m in methods_for("driven", Drive(eps, force, 1.0, Q))
                for k in m.driven_orders]

    stubs = {"candidates": lambda: [SimpleNamespace(method=m, order=1)
                                    for m in methods_for("period")],
             "ns_per_point": lambda c: 1.0, "_generated_q_cost": lambda k, lo, hi: 1.0,
             "_fourier_cost": lambda n, lo, hi: 1.0, "driven_truth": lambda *a: None,
             "driven_tradeoffs": tradeoffs,
             "emitted_driven": lambda name, k, *a: DrivenTradeoff(f"{name}, emitted", k, 1.0,
                                                                   {})}
    for name, stub in stubs.items():
        monkeypatch.setattr(fit, name, stub)
    rows = fit.measurements()
    assert {(q, str(m)) for q, m in rows} == {(q, m) for q, entries in COST_MODEL.items()
                                              for m in entries}
    entry = ("driven", "mu_expansion_damped, emitted")
    only = fit.measurements(entry)
    assert list(only) == [entry] and [k for k, _ in only[entry]] == [1, 2, 3, 4]
