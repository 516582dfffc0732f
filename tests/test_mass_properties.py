"""Tests for ar3cli.maths.mass_properties: textbook values, combination and validity checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from ar3cli.maths import mass_properties as mp

EXACT = 1e-9


def test_box_textbook() -> None:
    """Box 0.1 x 0.2 x 0.4 m, 2 kg: m(b^2+c^2)/12 etc."""
    props = mp.box((0.1, 0.2, 0.4), mass=2.0)
    assert props.mass == 2.0
    np.testing.assert_allclose(np.diag(props.inertia), [0.2 / 6, 0.17 / 6, 0.05 / 6], rtol=0, atol=EXACT)
    np.testing.assert_allclose(props.inertia - np.diag(np.diag(props.inertia)), 0.0, atol=EXACT)
    np.testing.assert_allclose(props.com, 0.0, atol=0)


def test_cylinder_textbook() -> None:
    props = mp.cylinder(0.1, 0.4, mass=1.0)
    np.testing.assert_allclose(np.diag(props.inertia), [0.0158333333333, 0.0158333333333, 0.005], atol=EXACT)


def test_sphere_textbook() -> None:
    props = mp.sphere(0.1, mass=1.0)
    np.testing.assert_allclose(np.diag(props.inertia), [0.004] * 3, atol=EXACT)


def test_volumes_and_density() -> None:
    assert mp.box_volume((0.1, 0.2, 0.4)) == pytest.approx(0.008, abs=EXACT)
    assert mp.cylinder_volume(0.1, 0.4) == pytest.approx(math.pi * 0.004, abs=EXACT)
    assert mp.sphere_volume(0.1) == pytest.approx(4.0 / 3.0 * math.pi * 0.001, abs=EXACT)
    assert mp.box((0.1, 0.2, 0.4), density=1000.0).mass == pytest.approx(8.0, abs=EXACT)
    assert mp.cylinder(0.1, 0.4, density=1000.0).mass == pytest.approx(1000 * math.pi * 0.004, abs=EXACT)
    assert mp.sphere(0.1, density=1000.0).mass == pytest.approx(4000 / 3 * math.pi * 0.001, abs=EXACT)


@pytest.mark.parametrize("kwargs", [{}, {"mass": 1.0, "density": 1.0}, {"mass": 0.0}, {"mass": -1.0}])
def test_mass_arguments_are_checked(kwargs: dict[str, float]) -> None:
    with pytest.raises(ValueError):
        mp.box((1, 1, 1), **kwargs)


def test_frozen_and_read_only() -> None:
    props = mp.sphere(0.1, mass=1.0)
    with pytest.raises(AttributeError):
        props.mass = 2.0  # type: ignore[misc]
    with pytest.raises(ValueError):
        props.inertia[0, 0] = 1.0


def test_rpy_to_matrix_convention() -> None:
    """URDF: R = Rz(yaw) Ry(pitch) Rx(roll); check single axes and the composition order."""
    np.testing.assert_allclose(mp.rpy_to_matrix((0, 0, math.pi / 2)) @ [1, 0, 0], [0, 1, 0], atol=EXACT)
    np.testing.assert_allclose(mp.rpy_to_matrix((math.pi / 2, 0, 0)) @ [0, 1, 0], [0, 0, 1], atol=EXACT)
    np.testing.assert_allclose(mp.rpy_to_matrix((0, math.pi / 2, 0)) @ [0, 0, 1], [1, 0, 0], atol=EXACT)
    # Fixed axes: roll is applied first, yaw last.
    rpy = (0.3, -0.7, 1.9)
    r, p, y = rpy
    expected = (
        mp.rpy_to_matrix((0, 0, y)) @ mp.rpy_to_matrix((0, p, 0)) @ mp.rpy_to_matrix((r, 0, 0))
    )
    np.testing.assert_allclose(mp.rpy_to_matrix(rpy), expected, atol=EXACT)
    rot = mp.rpy_to_matrix(rpy)
    np.testing.assert_allclose(rot @ rot.T, np.eye(3), atol=EXACT)
    assert np.linalg.det(rot) == pytest.approx(1.0, abs=EXACT)


def test_transformed_rotates_tensor_and_moves_com() -> None:
    """A box with its long side along z, rolled 90 deg about x, has its long side along y."""
    props = mp.box((0.1, 0.2, 0.4), mass=2.0)
    moved = mp.transformed(props, xyz=(1.0, 2.0, 3.0), rpy=(math.pi / 2, 0, 0))
    np.testing.assert_allclose(moved.com, [1, 2, 3], atol=EXACT)
    np.testing.assert_allclose(np.diag(moved.inertia), [0.2 / 6, 0.05 / 6, 0.17 / 6], atol=EXACT)
    # COM offset inside the transformed body is rotated too.
    shifted = mp.MassProperties(1.0, np.array([0.0, 1.0, 0.0]), np.eye(3))
    np.testing.assert_allclose(mp.transformed(shifted, rpy=(0, 0, math.pi / 2)).com, [-1, 0, 0], atol=EXACT)


def test_two_half_boxes_equal_one_box() -> None:
    """Parallel-axis theorem: two 1 kg halves of a box side by side equal the 2 kg box."""
    whole = mp.box((0.1, 0.2, 0.4), mass=2.0)
    half = mp.box((0.1, 0.2, 0.2), mass=1.0)
    both = mp.combine([mp.transformed(half, xyz=(0, 0, -0.1)), mp.transformed(half, xyz=(0, 0, 0.1))])
    assert both.mass == pytest.approx(2.0, abs=EXACT)
    np.testing.assert_allclose(both.com, 0.0, atol=EXACT)
    np.testing.assert_allclose(both.inertia, whole.inertia, atol=EXACT)


def test_combine_off_centre_and_single() -> None:
    """Two point-like spheres: COM is the mass-weighted mean, I_zz = sum m d^2."""
    a = mp.transformed(mp.sphere(1e-6, mass=1.0), xyz=(1.0, 0, 0))
    b = mp.transformed(mp.sphere(1e-6, mass=3.0), xyz=(-1.0, 0, 0))
    both = mp.combine([a, b])
    np.testing.assert_allclose(both.com, [-0.5, 0, 0], atol=EXACT)
    assert both.inertia[2, 2] == pytest.approx(1.0 * 1.5**2 + 3.0 * 0.5**2, abs=1e-9)
    assert both.inertia[0, 0] == pytest.approx(0.0, abs=1e-9)
    one = mp.combine([a])
    np.testing.assert_allclose(one.inertia, a.inertia, atol=EXACT)
    with pytest.raises(ValueError):
        mp.combine([])


def test_scaled_to_mass() -> None:
    props = mp.transformed(mp.cylinder(0.1, 0.4, mass=1.0), xyz=(0.1, 0, 0))
    heavier = mp.scaled_to_mass(props, 3.0)
    assert heavier.mass == 3.0
    np.testing.assert_allclose(heavier.com, props.com, atol=0)
    np.testing.assert_allclose(heavier.inertia, 3.0 * props.inertia, atol=EXACT)
    assert mp.cylinder(0.1, 0.4, density=7.0).inertia == pytest.approx(
        mp.scaled_to_mass(mp.cylinder(0.1, 0.4, density=1.0), 7 * mp.cylinder_volume(0.1, 0.4)).inertia
    )


def test_principal_moments_rotation_invariant() -> None:
    props = mp.combine([mp.box((0.1, 0.2, 0.4), mass=2.0), mp.transformed(mp.cylinder(0.05, 0.3, mass=1.0), (0.1, 0, 0))])
    expected = mp.principal_moments(props.inertia)
    for rpy in [(0.1, 0.2, 0.3), (math.pi, -1.0, 2.5), (-0.7, 1.5, 0.0)]:
        rotated = mp.transformed(props, rpy=rpy)
        np.testing.assert_allclose(mp.principal_moments(rotated.inertia), expected, atol=EXACT)
    assert list(expected) == sorted(expected)


def test_positive_definite() -> None:
    assert mp.is_positive_definite(mp.box((0.1, 0.2, 0.4), mass=2.0).inertia)
    assert not mp.is_positive_definite(np.diag([1.0, 1.0, 0.0]))
    assert not mp.is_positive_definite(np.diag([1.0, -1.0, 1.0]))
    # Positive diagonal but a large product of inertia: indefinite.
    assert not mp.is_positive_definite([[1.0, 2.0, 0.0], [2.0, 1.0, 0.0], [0.0, 0.0, 1.0]])


def test_triangle_inequality() -> None:
    assert mp.satisfies_triangle_inequality(mp.box((0.1, 0.2, 0.4), mass=2.0).inertia)
    # A thin plate reaches equality exactly: I_zz = I_xx + I_yy.
    assert mp.satisfies_triangle_inequality(mp.box((0.3, 0.2, 0.0), mass=1.0).inertia)
    assert mp.satisfies_triangle_inequality(mp.transformed(mp.box((0.3, 0.2, 0.0), mass=1.0), rpy=(0.4, 0.5, 0.6)).inertia, tol=1e-12)
    # Positive definite but physically impossible.
    bad = np.diag([1.0, 1.0, 3.0])
    assert mp.is_positive_definite(bad)
    assert not mp.satisfies_triangle_inequality(bad)
    assert not mp.satisfies_triangle_inequality(np.diag([1.0, 1.0, 2.0 + 1e-6]), tol=1e-9)
    assert mp.satisfies_triangle_inequality(np.diag([1.0, 1.0, 2.0 + 1e-10]), tol=1e-9)
