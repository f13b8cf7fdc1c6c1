"""Studies: sweeps over operating points, Monte Carlo samples and calibration tables.

``run_sweep(scene, out_dir, task="simulate"|"optimize", grid=[...] or samples=N, engine=...)``
runs one simulation or optimisation per point on local worker processes or a Dask cluster,
streams one row per point into ``results.csv`` (an interrupted sweep resumes), and draws the
figures. See the README section "Sweeps, calibration maps and Monte Carlo".
"""

from .executor import ENGINES, StudyInterrupted, execute
from .points import grid_points, parse_grid, point_id
from .run import run_sweep, study_points
from .tasks import Task, run_unit

__all__ = ["ENGINES", "StudyInterrupted", "Task", "execute", "grid_points", "parse_grid", "point_id", "run_sweep",
           "run_unit", "study_points"]
