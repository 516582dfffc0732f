"""info: what a user wants to see first about a robot (tree, DOF, mass, size, meshes), no pybullet."""
