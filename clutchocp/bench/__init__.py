"""Benchmarks: how far to trust a result, and how fast IDAS is against its peers at matched error.

* :func:`run_bench` -- the ``clutchocp bench`` command: work-precision of IDAS against CVODES and
  scipy's Radau, BDF and LSODA, stiffness along each trajectory, run time against pack size and
  the convergence of the optimal engagement pressure with the collocation mesh;
* :mod:`~clutchocp.bench.workprecision` -- error measures, references, sweeps, matched-error ratios;
* :mod:`~clutchocp.bench.scaling` -- run time against the number of plate pairs;
* :mod:`~clutchocp.bench.optimization` -- collocation errors against solve time.
"""

from .progress import Progress
from .run import format_summary, run_bench
from .scaling import growth_exponent, plate_pair_scaling
from .workprecision import speedups, sweep, time_at_error, trajectory_errors

__all__ = ["Progress", "format_summary", "growth_exponent", "plate_pair_scaling", "run_bench", "speedups", "sweep", "time_at_error",
           "trajectory_errors"]
