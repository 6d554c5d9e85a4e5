"""Comparison studies (``mitos compare``): worlds x operator choices x seeded runs.

| module | holds |
| --- | --- |
| `spec.py` | `Choice` (planner + norms + inference), `Task`, `make_choices`, `expand`, paired seeds |
| `simtask.py` | `run_task(context, task)`: one task through the simulator -> one flat result |
| `executors.py` | `execute(fn, tasks, "local" / "dask", ...)`: serial, process pool, Dask |
| `store.py` | `results.csv` written row by row (fsync), `--resume`, `study.json` |
| `stats.py` | Wilson and Student-t intervals (math + NumPy, no SciPy) |
| `summary.py` | per world x choice summaries, ranking, paired McNemar test |
| `report.py` | the rich tables and `report.md` |
| `run.py` | `Study`, `run_study`, `write_report` |

The simulator and Dask are imported only when a study runs.
"""

from .run import Outcome, Study, run_study, write_report
from .spec import Choice, Task, expand, make_choices

__all__ = ["Choice", "Outcome", "Study", "Task", "expand", "make_choices", "run_study",
           "write_report"]
