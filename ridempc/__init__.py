"""ridempc: legged robots riding boards in simulation, with MPC and whole-body control.

``ridempc.ride(robot, board, controller, scenario, seed=...)`` rides once and returns the
summary (:func:`ridempc.api.ride`); it is imported on first use, so that ``import ridempc``
stays light.

On a machine without a display, MuJoCo's offscreen rendering uses EGL unless the user
chose a backend; this must be set before MuJoCo is first imported.
"""

import os as _os
from typing import TYPE_CHECKING as _TYPE_CHECKING
from typing import Any as _Any

if _TYPE_CHECKING:
    from ridempc.api import ride

if "MUJOCO_GL" not in _os.environ and not _os.environ.get("DISPLAY"):
    _os.environ["MUJOCO_GL"] = "egl"

__version__ = "0.1.0"
__all__ = ["__version__", "ride"]


def __getattr__(name: str) -> _Any:
    if name == "ride":
        from ridempc.api import ride

        return ride
    raise AttributeError(f"module 'ridempc' has no attribute '{name}'")
