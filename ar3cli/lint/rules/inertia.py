"""Inertia rules (I): what PyBullet does with missing, zero or unphysical mass properties."""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import lru_cache

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.physics.tensor_math import is_positive_definite, satisfies_triangle_inequality, symmetric_eigenvalues

IMPLAUSIBLE_FACTOR = 3.0
"""Radius of gyration above this many half-diagonals of the geometry's box cannot be real (see I007)."""
TRIANGLE_TOLERANCE = 1e-3
"""Relative slack for A + B >= C: thin disks and rods sit exactly on the boundary, and files round."""


def _moving_links(model) -> dict[str, object]:
    """Link name -> the moving joint it hangs from."""
    return {joint.child: joint for joint in model.joints if joint.moves and joint.child}


@lru_cache(maxsize=4096)
def tensor_moments(tensor: tuple[float, ...]) -> tuple[float, float, float]:
    """Principal moments of an (ixx, ixy, ixz, iyy, iyz, izz) tensor; cached, as I004, I005 and I007 all ask."""
    ixx, ixy, ixz, iyy, iyz, izz = tensor
    return symmetric_eigenvalues(((ixx, ixy, ixz), (ixy, iyy, iyz), (ixz, iyz, izz)))


def finite_tensor(tensor) -> bool:
    return tensor is not None and all(map(math.isfinite, tensor))


def _fmt(moments) -> str:
    return "(" + ", ".join(f"{m:.4g}" for m in moments) + ")"


@rule("I001", "inertial-missing", "error", "Moving link without <inertial>",
      why="""PyBullet gives a link without <inertial> a mass of 1 kg and an inertia of (1, 1, 1),
      silently apart from a C-level warning. On a small arm that is kilograms of phantom mass at
      the wrist; MuJoCo instead computes it from the geometry at water density.""",
      fix="Add an <inertial> with the real mass, COM and tensor (ar3cli fix-inertia can compute one).",
      bad=arm(link_extra=""), good=arm())
def inertial_missing(ctx) -> Iterator[Hit]:
    moving = _moving_links(ctx.model)
    for link in ctx.model.links:
        if link.inertial is None and link.name in moving:
            yield Hit(f"link '{link.name}' moves (joint '{moving[link.name].name}') but has no <inertial>: "
                      "PyBullet uses 1 kg and I = 1", link.element)


@rule("I002", "fixed-link-inertial-missing", "warning", "Link on a fixed joint without <inertial>",
      why="""A frame link (tool tip, sensor frame) hangs from a fixed joint and often has neither
      geometry nor <inertial>. PyBullet still gives it 1 kg and I = 1, so every tcp/camera frame adds
      a kilogram to the arm's end.""",
      fix="Add a tiny <inertial> (mass 1e-6 kg, I = 1e-12: measured to act like mass 0 within 3e-6 N·m) or run ar3cli fix-inertia.",
      bad=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="tcp"/>
          <joint name="tcp_joint" type="fixed"><parent link="base"/><child link="tcp"/></joint>"""),
      good=robot(f"""
          <link name="base">{LINK_INERTIAL}</link>
          <link name="tcp"><inertial><mass value="1e-6"/><inertia ixx="1e-12" ixy="0" ixz="0" iyy="1e-12" iyz="0" izz="1e-12"/></inertial></link>
          <joint name="tcp_joint" type="fixed"><parent link="base"/><child link="tcp"/></joint>"""))
def fixed_link_inertial_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        link = ctx.model.link(joint.child) if joint.type == "fixed" and joint.child else None
        if link is None or link.inertial is not None or link.name == "world":
            continue
        kind = "has geometry" if link.has_geometry else "is a frame (no geometry)"
        yield Hit(f"link '{link.name}' {kind} on fixed joint '{joint.name}' without <inertial>: "
                  "PyBullet adds 1 kg and I = 1", link.element)


@rule("I003", "mass-not-positive", "error", "Mass missing, zero or negative on a moving link",
      why="""A moving body needs positive mass. PyBullet treats mass 0 as static (the link stops
      following the physics), negative mass makes the dynamics diverge, and MuJoCo refuses both.""",
      fix="Set the link's real mass in kg.",
      bad=arm(link_extra='<inertial><mass value="0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'),
      good=arm())
def mass_not_positive(ctx) -> Iterator[Hit]:
    moving = _moving_links(ctx.model)
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or link.name not in moving:
            continue
        mass_element = inertial.element.find("mass")
        if mass_element is None or mass_element.get("value") is None:
            yield Hit(f"link '{link.name}' <inertial> has no <mass value=...>", inertial.element)
        elif inertial.mass is not None and not inertial.mass > 0:
            yield Hit(f"link '{link.name}' moves but has mass {inertial.mass:g} kg", mass_element)


def _tensor_hits(ctx, test):
    """Yield (link, inertial, moments) for links with a finite, non-zero tensor where ``test`` fails."""
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or not finite_tensor(inertial.tensor) or not any(inertial.tensor):
            continue
        moments = tensor_moments(inertial.tensor)
        if not test(inertial, moments):
            yield link, inertial, moments


@rule("I004", "inertia-not-positive-definite", "error", "Inertia tensor is not positive definite",
      why="""Every principal moment of a real body is positive. A zero or negative one makes the
      mass matrix singular or indefinite: PyBullet warns and the simulation drifts or explodes,
      MuJoCo and Drake refuse or substitute the tensor.""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="-0.01" iyz="0" izz="0.01"/></inertial>'),
      good=arm())
def inertia_not_positive_definite(ctx) -> Iterator[Hit]:
    for link, inertial, moments in _tensor_hits(ctx, lambda inertial, _m: is_positive_definite(inertial.matrix())):
        yield Hit(f"link '{link.name}' inertia is not positive definite: principal moments {_fmt(moments)}",
                  inertial.element.find("inertia"))


@rule("I005", "inertia-triangle", "error", "Inertia violates the triangle inequality",
      why="""For a real body each principal moment is at most the sum of the other two
      (A + B >= C). A tensor that breaks it cannot belong to any mass distribution; MuJoCo refuses
      it ("inertia must satisfy A + B >= C") and PyBullet simulates a body that cannot exist.""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.05"/></inertial>'),
      good=arm())
def inertia_triangle(ctx) -> Iterator[Hit]:
    def ok(inertial, moments) -> bool:
        return moments[0] <= 0 or satisfies_triangle_inequality(inertial.matrix(), tol=TRIANGLE_TOLERANCE * moments[-1])

    for link, inertial, moments in _tensor_hits(ctx, ok):
        a, b, c = moments
        yield Hit(f"link '{link.name}' principal moments {_fmt(moments)}: {a:.4g} + {b:.4g} < {c:.4g}",
                  inertial.element.find("inertia"))


@rule("I006", "inertia-zero", "error", "All-zero or missing inertia tensor with positive mass",
      why="""A body with mass but no rotational inertia (ixx = iyy = izz = 0, or no <inertia>) is a
      point mass: PyBullet divides by the zero moments and the joint accelerations blow up.""",
      fix="Compute the tensor from the geometry (box: m(y²+z²)/12 ...; ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>'),
      good=arm())
def inertia_zero(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or not (inertial.mass or 0) > 0:
            continue
        element = inertial.element.find("inertia")
        if element is None:
            yield Hit(f"link '{link.name}' has mass {inertial.mass:g} kg but no <inertia>", inertial.element)
        elif inertial.tensor is not None and not any(inertial.tensor):
            yield Hit(f"link '{link.name}' has mass {inertial.mass:g} kg and an all-zero inertia tensor", element)


@rule("I007", "inertia-implausible", "warning", "Inertia implausible for the link's geometry",
      why="""The radius of gyration sqrt(I_max / m) of a body is at most the size of the body (about
      its COM it cannot exceed the diagonal of its bounding box). A much larger value means the
      tensor belongs to something else: a placeholder I = 1 on a 0.1 kg link, grams vs kilograms, or
      g·mm² vs kg·m². The link then swings like a body many metres wide.""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="0.1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
                         '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'),
      good=arm(link_extra=LINK_INERTIAL + '<collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision>'))
def inertia_implausible(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or not finite_tensor(inertial.tensor) or not (inertial.mass or 0) > 0 \
                or not math.isfinite(inertial.mass):
            continue
        bounds = ctx.link_bounds(link)
        if bounds is None:
            continue
        half_diagonal = 0.5 * math.dist(bounds[0], bounds[1])
        moments = tensor_moments(inertial.tensor)
        if half_diagonal <= 0 or moments[-1] <= 0:
            continue
        gyration = math.sqrt(moments[-1] / inertial.mass)
        if gyration > IMPLAUSIBLE_FACTOR * half_diagonal:
            yield Hit(f"link '{link.name}' radius of gyration {gyration:.3g} m is {gyration / half_diagonal:.0f}x "
                      f"its geometry's half-diagonal {half_diagonal:.3g} m (mass {inertial.mass:g} kg, "
                      f"I_max {moments[-1]:.3g} kg·m²)", inertial.element.find("inertia"))


RULES = (inertial_missing, fixed_link_inertial_missing, mass_not_positive, inertia_not_positive_definite,
         inertia_triangle, inertia_zero, inertia_implausible)
