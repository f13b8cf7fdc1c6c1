"""``clutchocp robust``: Monte Carlo proof of shift-control strategies over a scene's uncertainty.

The strategies and the Monte Carlo are :mod:`clutchocp.shiftcontrol.workflow`'s, the figures
:mod:`clutchocp.shiftcontrol.figures`'; :func:`run_robust` runs them and writes summary.json,
samples.csv and three figures.
"""

import sys
import time
from pathlib import Path

import numpy as np
from tqdm import tqdm

from ..errors import ModelError
from ..output import write_csv, write_summary
from ..scene import default_scene, load_scene
from ..scene.uncertainty import Uncertainty
from .figures import plot_distributions, plot_envelopes, plot_jump_vs_fields
from .spec import load_slip_spec
from .export import write_commands
from .workflow import (
    COLUMNS,
    STRATEGIES,
    build_strategies,
    check_strategies,
    cpu_count,
    format_summary,
    monte_carlo,
    robust_summary,
)


def run_robust(scene=None, out_dir="out/robust", *, samples=200, seed=0, uncertain=(), t_max=None,
               controller="slip_lqr", workers=None, intervals=60, progress=True, strategies=STRATEGIES):
    """Monte Carlo of the shift-control strategies of a scene; writes summary.json, samples.csv, figures.

    Parameters
    ----------
    scene : Scene, str or Path, optional
        Engagement scene (default: the default scene).
    out_dir : str or Path
    samples : int
        Number of draws of the uncertainty.
    seed : int
        Seed of the draws (same seed, same draws, same numbers).
    uncertain : sequence of str
        ``"part.key=spec"`` texts added to (or replacing) the scene's [uncertainty].
    t_max : float, optional
        Engagement-time limit [s] of the optimisations and of the lock-within-t_max share
        (default: the lock-up time of the scene's own profile, as ``clutchocp optimize``).
    controller : str or Path
        Slip-feedback spec (built-in name or TOML file).
    workers : int, optional
        Processes (default: the local cores).
    intervals : int
        Collocation intervals of the optimisations.
    strategies : sequence of str
        Which of ``baseline``, ``nominal_optimum``, ``robust_feedforward``, ``closed_loop`` to run (default: all).

    Returns
    -------
    dict: the summary (plus ``files``).
    """
    say = (lambda *a: print(*a, file=sys.stderr)) if progress else (lambda *a: None)
    if scene is None:
        scene = default_scene()
    elif isinstance(scene, (str, Path)):
        scene = load_scene(scene)
    for name, value, allowed in (("samples", samples, False), ("workers", workers, True),
                                 ("intervals", intervals, False)):
        if value is None and allowed:
            continue
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < 1:
            raise ModelError(f"{name} = {value!r}: must be a whole number >= 1")
    chosen = check_strategies(strategies)
    spec = load_slip_spec(controller)
    uncertainty = Uncertainty.from_scene(scene, extra=tuple(uncertain))
    if not uncertainty:
        raise ModelError(f"scene '{scene.name}' declares no uncertainty: add an [uncertainty] table or "
                         "--uncertain \"friction.mu=uniform 10 %\"")
    nominal = scene.without_uncertainty()
    start = time.perf_counter()
    strategies, facts = build_strategies(nominal, uncertainty, spec, t_max=t_max, intervals=intervals, say=say,
                                         chosen=chosen)
    setup = time.perf_counter() - start
    bar = _progress_bar(samples + 1, progress)          # the centre and the draws
    rows, t_end, mc_time, n_runs = monte_carlo(nominal, uncertainty, strategies, facts, samples=samples, seed=seed,
                                               workers=workers, progress=bar)
    if bar is not None:
        bar.close()
    timing = {"setup_s": setup, "monte_carlo_s": mc_time, "samples_per_s": n_runs / mc_time,
              "workers": workers or cpu_count()}
    summary = robust_summary(scene, spec, uncertainty, strategies, facts, rows, samples=samples, seed=seed,
                             t_end=t_end, timing=timing)
    t_max = facts["t_max_s"]
    centre = [r for r in rows if r["sample"] == -1]
    drawn = [r for r in rows if r["sample"] >= 0]
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    files = [write_summary(out / "summary.json", summary), _write_samples(out / "samples.csv", rows, uncertainty)]
    shown = [s for s in strategies if not s.notes.get("centre_only")]
    target = spec.acceptance["jump_p95_pct"] if "closed_loop" in chosen else None
    files += plot_jump_vs_fields(out, drawn, uncertainty, shown, target)
    files.append(plot_distributions(out, drawn, shown, t_max, target))
    files.append(plot_envelopes(out, drawn, centre, shown, t_max))
    files += write_commands(out, strategies, facts)
    summary["files"] = [str(f) for f in files]
    if progress:
        print(format_summary(summary))
    return summary


def _progress_bar(total, enabled):
    if not enabled:
        return None
    bar = tqdm(total=total, desc="samples", unit="sample", file=sys.stderr)

    def update(done, _total):
        bar.n = done
        bar.refresh()
    update.close = bar.close
    return update


def _write_samples(path, rows, uncertainty):
    fields = list(uncertainty.names)
    columns = {"sample": [r["sample"] for r in rows], "strategy": [r["strategy"] for r in rows]}
    for f in fields:
        columns[f] = [r.get(f) for r in rows]
    draws = list(dict.fromkeys(k for r in rows for k in r.get("sensor_draws", {})))
    for key in draws:
        columns[key] = ["" if r.get("sensor_draws", {}).get(key) is None else r["sensor_draws"][key] for r in rows]
    columns["locked"] = [int(r["locked"]) for r in rows]
    columns["locked_within_t_max"] = [int(r["locked_within_t_max"]) for r in rows]
    for key, name in COLUMNS:
        columns[name] = ["" if r[key] is None else r[key] for r in rows]
    return write_csv(path, columns)
