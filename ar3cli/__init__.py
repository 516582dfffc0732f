"""ar3cli: diagnose, fix and sim-check robot description files (URDF and xacro) with PyBullet."""

__version__ = "0.1.0"
