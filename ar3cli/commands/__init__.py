"""One module per CLI command. Each keeps heavy imports (pybullet, trimesh, numpy) inside
its function so that ``ar3cli --help`` and static lint stay fast."""
