"""The GPU backend's tests run on Warp's CPU device; they are skipped only where mujoco_warp
cannot be imported (the ``gpu`` extra is not installed)."""
