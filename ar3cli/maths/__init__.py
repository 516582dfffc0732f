"""Tensor maths and mass properties of primitives: pure numbers, no robot files, no engines."""
