"""cross-check: the same robot in PyBullet and MuJoCo, compared quantity by quantity."""
