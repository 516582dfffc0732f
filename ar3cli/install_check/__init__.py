"""install-check: what this environment can run (imports, pybullet, optional capabilities), each probed in a child."""
