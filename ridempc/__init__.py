"""ridempc: legged robots riding boards in simulation, with MPC and whole-body control.

On a machine without a display, MuJoCo's offscreen rendering uses EGL unless the user
chose a backend; this must be set before MuJoCo is first imported.
"""

import os as _os

if "MUJOCO_GL" not in _os.environ and not _os.environ.get("DISPLAY"):
    _os.environ["MUJOCO_GL"] = "egl"

__version__ = "0.1.0"
__all__ = ["__version__"]
