"""``ar3cli diff``: what a change to a robot description does to the robot (structure, kinematics,
dynamics, limits, geometry, lint findings), compared semantically, never as text."""
