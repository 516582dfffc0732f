"""Inertia rules (I): what PyBullet does with missing, zero or unphysical mass properties."""

from __future__ import annotations

import math
from collections.abc import Iterator
from functools import lru_cache

from ar3cli.lint.rules.base import LINK_INERTIAL, Hit, arm, robot, rule
from ar3cli.lint.rules.plausibility import density_implausible, grams_evidence
from ar3cli.maths.tensor_math import is_positive_definite, satisfies_triangle_inequality, symmetric_eigenvalues

IMPLAUSIBLE_FACTOR = 3.0
"""Radius of gyration above this many half-diagonals of the geometry's box cannot be real (see I007)."""
TRIANGLE_TOLERANCE = 1e-3
"""Relative slack for A + B >= C: thin disks and rods sit exactly on the boundary, and files round."""
MJ_MINVAL = 1e-15
"""MuJoCo's ``mjMINVAL`` (mjtnum.h): a moving body whose mass or any principal moment is below it
is refused ("mass and inertia of moving bodies must be larger than mjMINVAL", user_model.cc)."""
EFFECTIVELY_ZERO = MJ_MINVAL
"""kg·m²: a tensor whose every principal moment is smaller than this in magnitude is zero written
with rounding noise (icub.urdf: (-1.355e-20, 0, 1.355e-20)). A 1 mg part 1 cm across already has
1e-10; MuJoCo reads anything below mjMINVAL as zero."""
NEAR_SINGULAR_RATIO = 1e-9
"""Smallest / largest principal moment below which a tensor is near-singular. A real body cannot get
there: a rod's ratio is 6 (r/L)², 1e-9 would be a 1 m rod 13 µm thick."""
FRAME_LINK_PHRASE = "is a frame (no geometry)"
"""I002's words for a link with neither geometry nor <inertial> on a fixed joint: fix-inertia gives such
a frame a tiny inertial without any mass source, so ``lint-urdf --fix-hint`` asks for no --density."""


def _moving_links(model) -> dict[str, object]:
    """Link name -> the moving joint it hangs from."""
    return {joint.child: joint for joint in model.joints if joint.moves and joint.child}


def effectively_zero(moments) -> bool:
    """True when every principal moment is below :data:`EFFECTIVELY_ZERO` in magnitude."""
    return all(abs(m) < EFFECTIVELY_ZERO for m in moments)


def near_singular(moments) -> bool:
    """True for a positive tensor whose smallest moment is below mjMINVAL or 1e-9 of the largest."""
    smallest, largest = moments[0], moments[-1]
    return 0 < smallest < max(MJ_MINVAL, NEAR_SINGULAR_RATIO * largest) and not effectively_zero(moments)


def _valid_body(inertial, moments) -> bool:
    """A tensor some body could have: positive definite, A + B >= C, not near-singular (else I004, I005, I009)."""
    return moments[0] > 0 and _triangle_ok(inertial, moments) and not near_singular(moments)


def _triangle_ok(inertial, moments) -> bool:
    return moments[0] <= 0 or satisfies_triangle_inequality(inertial.matrix(), tol=TRIANGLE_TOLERANCE * moments[-1])


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
      engines=("pybullet", "mujoco", "drake", "gazebo"),
      breaks="PyBullet simulates the link as 1 kg with I = 1 (measured), MuJoCo invents its mass from the "
             "geometry at water density, Gazebo drops the link.",
      why="""PyBullet gives a link without <inertial> a mass of 1 kg and an inertia of (1, 1, 1),
      silently apart from a C-level warning. On a small arm that is kilograms of phantom mass at
      the wrist; MuJoCo instead computes it from the geometry at water density.""",
      fix="Add an <inertial> with the real mass, COM and tensor (ar3cli fix-inertia can compute one).",
      bad=arm(link_extra=""), good=arm(), fixed_by="fix-inertia",
      references="PyBullet UrdfParser.cpp parseLink (no <inertial>: mass 1, inertia 1 unless the link is named "
                 "'world'); docs/pybullet-facts.md.")
def inertial_missing(ctx) -> Iterator[Hit]:
    moving = _moving_links(ctx.model)
    phantom_only = not set(ctx.targets) & REFUSE_MASSLESS
    for link in ctx.model.links:
        if link.inertial is None and link.name in moving:
            if phantom_only and translating_frame(ctx, link) is not None:
                continue  # PyBullet's 1 kg on a frame that only translates, carrying far more: I017's, an info
            yield Hit(f"link '{link.name}' moves (joint '{moving[link.name].name}') but has no <inertial>: "
                      "PyBullet uses 1 kg and I = 1", link.element)


PHANTOM_SHARE = 0.02
"""PyBullet's 1 kg on a frame that only translates is at most this share of the mass it carries (I017)."""
REFUSE_MASSLESS = frozenset({"mujoco", "drake", "gazebo"})
"""Targets for which a moving link without <inertial> is an error whatever it carries: MuJoCo refuses a moving
body without mass (below mjMINVAL), Drake's is singular, Gazebo drops the link."""


def translating_frame(ctx, link) -> float | None:
    """The mass (kg, from the file) that ``link``'s prismatic joint moves, when ``link`` is a frame of a virtual
    planar base: no <inertial> and no geometry, every joint from a geometry-less root down to it prismatic (or
    fixed), so it never rotates and its I = 1 plays no part; and PyBullet's 1 kg is at most PHANTOM_SHARE of what
    it carries. None otherwise."""
    from ar3cli.lint.rules.plausibility import subtree_masses

    if link.inertial is not None or link.has_geometry:
        return None
    above = list(ctx.model.joints_above(link.name))
    if not above or above[0].type != "prismatic" or any(j.type not in ("prismatic", "fixed") for j in above):
        return None
    root = ctx.model.link(above[-1].parent) if above[-1].parent else None
    if root is None or root.has_geometry or ctx.model.parent_joint(root.name) is not None:
        return None
    carried = ctx.shared("subtree-masses", subtree_masses)[link.name]
    return carried if carried > 0 and PHANTOM_SHARE * carried >= 1.0 else None


@rule("I017", "translating-frame-inertial-missing", "info", "A planar base's virtual link without <inertial>",
      engines=("pybullet",),
      why="""A mobile base moved in the plane is often written as a chain of virtual links: x and y prismatic
      joints from a fixed root, then the yaw joint to the chassis (Clearpath's Ridgeback). Its x/y links have
      no <inertial>: PyBullet gives each 1 kg and I = 1, but they never rotate, so the inertia plays no part,
      and a kilogram on a base of a hundred moves it barely differently (measured with pybullet 3.2.7 on a
      165 kg base with two such links: 1.2% less travel under the same force, yaw unchanged). I001 reports
      such a link when the 1 kg is a larger share of what it carries, or when --target names MuJoCo, Drake
      or Gazebo (MuJoCo refuses a moving body without mass).""",
      fix="Give the virtual links a tiny <inertial> (mass 1e-6 kg, I = 1e-12), or leave them.",
      bad=robot("""
          <link name="odom"/><link name="x_link"/>
          <link name="chassis"><inertial><mass value="165"/><inertia ixx="4" ixy="0" ixz="0" iyy="8" iyz="0" izz="10"/></inertial></link>
          <joint name="x" type="prismatic"><parent link="odom"/><child link="x_link"/><axis xyz="1 0 0"/>
            <limit lower="-100" upper="100" effort="100" velocity="1"/></joint>
          <joint name="yaw" type="continuous"><parent link="x_link"/><child link="chassis"/><axis xyz="0 0 1"/></joint>"""),
      good=robot("""
          <link name="odom"/>
          <link name="x_link"><inertial><mass value="1e-6"/><inertia ixx="1e-12" ixy="0" ixz="0" iyy="1e-12" iyz="0" izz="1e-12"/></inertial></link>
          <link name="chassis"><inertial><mass value="165"/><inertia ixx="4" ixy="0" ixz="0" iyy="8" iyz="0" izz="10"/></inertial></link>
          <joint name="x" type="prismatic"><parent link="odom"/><child link="x_link"/><axis xyz="1 0 0"/>
            <limit lower="-100" upper="100" effort="100" velocity="1"/></joint>
          <joint name="yaw" type="continuous"><parent link="x_link"/><child link="chassis"/><axis xyz="0 0 1"/></joint>"""),
      thresholds="A link without <inertial> and geometry whose parent joint is prismatic, every joint above it "
                 "prismatic or fixed from a root without geometry, carrying at least 1 kg / PHANTOM_SHARE = 50 kg; "
                 "only when --target names none of MuJoCo, Drake, Gazebo (else I001).")
def translating_frame_inertial_missing(ctx) -> Iterator[Hit]:
    if set(ctx.targets) & REFUSE_MASSLESS:
        return
    for link in ctx.model.links:
        carried = translating_frame(ctx, link)
        if carried is not None:
            joint = ctx.model.parent_joint(link.name)
            yield Hit(f"link '{link.name}' (prismatic joint '{joint.name}') has no <inertial>: PyBullet gives it 1 kg, "
                      f"{100 / carried:.1g}% of the {carried:g} kg it carries, and I = 1, which plays no part: it never "
                      "rotates", link.element)


@rule("I002", "fixed-link-inertial-missing", "warning", "Link on a fixed joint without <inertial>",
      engines=("pybullet",),
      why="""A frame link (tool tip, sensor frame) hangs from a fixed joint and often has neither
      geometry nor <inertial>. PyBullet still gives it 1 kg and I = 1, so every tcp/camera frame adds
      a kilogram to the arm's end. A link welded to the root (the base's frames, a mounting plate's
      markers) belongs to the base: its kilogram matters only if the robot floats, which I012 says, once
      for the base, at info.""",
      fix="Add a tiny <inertial> (mass 1e-6 kg, I = 1e-12: measured to act like mass 0 within 3e-6 N·m) or run ar3cli fix-inertia.",
      bad=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="arm">{LINK_INERTIAL}</link><link name="tcp"/>
          <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
          <joint name="tcp_joint" type="fixed"><parent link="arm"/><child link="tcp"/></joint>"""),
      good=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="arm">{LINK_INERTIAL}</link>
          <link name="tcp"><inertial><mass value="1e-6"/><inertia ixx="1e-12" ixy="0" ixz="0" iyy="1e-12" iyz="0" izz="1e-12"/></inertial></link>
          <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/><axis xyz="0 0 1"/>
            <limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
          <joint name="tcp_joint" type="fixed"><parent link="arm"/><child link="tcp"/></joint>"""),
      fixed_by="fix-inertia")
def fixed_link_inertial_missing(ctx) -> Iterator[Hit]:
    for joint in ctx.model.joints:
        link = ctx.model.link(joint.child) if joint.type == "fixed" and joint.child else None
        if link is None or link.inertial is not None or link.name == "world" or _welded_to_root(ctx, link):
            continue
        kind = "has geometry" if link.has_geometry else FRAME_LINK_PHRASE
        yield Hit(f"link '{link.name}' {kind} on fixed joint '{joint.name}' without <inertial>: "
                  "PyBullet adds 1 kg and I = 1", link.element)


@rule("I003", "mass-not-positive", "error", "Mass missing, zero or negative on a moving link",
      engines=("pybullet", "mujoco", "drake", "gazebo"),
      refused_by=("mujoco",),
      breaks="PyBullet makes a mass-0 link static and diverges on a negative mass; MuJoCo refuses the file.",
      why="""A moving body needs positive mass. PyBullet treats mass 0 as static (the link stops
      following the physics), negative mass makes the dynamics diverge, and MuJoCo refuses both.""",
      fix="Set the link's real mass in kg.",
      bad=arm(link_extra='<inertial><mass value="0"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>'),
      good=arm(), fixed_by="fix-inertia")
def mass_not_positive(ctx) -> Iterator[Hit]:
    moving = _moving_links(ctx.model)
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or link.name not in moving:
            continue
        mass_element = inertial.first_child("mass")
        if mass_element is None or mass_element.get("value") is None:
            yield Hit(f"link '{link.name}' <inertial> has no <mass value=...>", inertial.element)
        elif inertial.mass is not None and not inertial.mass > 0:
            yield Hit(f"link '{link.name}' moves but has mass {inertial.mass:g} kg", mass_element)


def _tensor_hits(ctx, test):
    """Yield (link, inertial, moments) for links with a finite tensor that is not (effectively) zero
    where ``test`` fails; zero tensors are I006's and I008's."""
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or not finite_tensor(inertial.tensor) or not any(inertial.tensor):
            continue
        moments = tensor_moments(inertial.tensor)
        if not effectively_zero(moments) and not test(inertial, moments):
            yield link, inertial, moments


@rule("I004", "inertia-not-positive-definite", "error", "Inertia tensor is not positive definite",
      engines=("pybullet", "mujoco", "drake", "gazebo"),
      refused_by=("mujoco",),
      breaks="MuJoCo refuses the body and Drake substitutes the tensor; PyBullet loaded with "
             "URDF_USE_INERTIA_FROM_FILE drifts or explodes.",
      why="""Every principal moment of a real body is positive. A zero or negative one makes the
      mass matrix singular or indefinite: PyBullet warns and the simulation drifts or explodes,
      MuJoCo and Drake refuse or substitute the tensor. Tensors that are zero apart from rounding
      noise (every moment below 1e-15) are I006's.""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="-0.01" iyz="0" izz="0.01"/></inertial>'),
      good=arm(), fixed_by="fix-inertia",
      thresholds="Tensors whose every principal moment is below EFFECTIVELY_ZERO = 1e-15 kg·m² are left to I006/I008.")
def inertia_not_positive_definite(ctx) -> Iterator[Hit]:
    for link, inertial, moments in _tensor_hits(ctx, lambda inertial, _m: is_positive_definite(inertial.matrix())):
        yield Hit(f"link '{link.name}' inertia is not positive definite: principal moments {_fmt(moments)}",
                  inertial.first_child("inertia"))


@rule("I005", "inertia-triangle", "error", "Inertia violates the triangle inequality",
      engines=("pybullet", "mujoco", "drake", "gazebo"),
      refused_by=("mujoco",),
      breaks='MuJoCo refuses the file ("inertia must satisfy A + B >= C"); PyBullet simulates a body that cannot '
             "exist.",
      why="""For a real body each principal moment is at most the sum of the other two
      (A + B >= C). A tensor that breaks it cannot belong to any mass distribution; MuJoCo refuses
      it ("inertia must satisfy A + B >= C") and PyBullet simulates a body that cannot exist.""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.05"/></inertial>'),
      good=arm(), fixed_by="fix-inertia",
      thresholds="A + B >= C - TRIANGLE_TOLERANCE x C, TRIANGLE_TOLERANCE = 1e-3; tensors whose every moment is "
                 "below 1e-15 kg·m² are effectively zero (I006/I008), not triangle violations.")
def inertia_triangle(ctx) -> Iterator[Hit]:
    for link, inertial, moments in _tensor_hits(ctx, _triangle_ok):
        a, b, c = moments
        tiny = " (the two smallest are below MuJoCo's mjMINVAL 1e-15: a line, not a body)" if b < MJ_MINVAL else ""
        yield Hit(f"link '{link.name}' principal moments {_fmt(moments)}: {a:.4g} + {b:.4g} < {c:.4g}{tiny}",
                  inertial.first_child("inertia"))


def _zero_tensor_hits(ctx, in_inert_body: bool) -> Iterator[Hit]:
    """I006 (``in_inert_body``) and I008: positive mass with a zero or effectively zero tensor, split by
    whether the rigid body the link is welded into (fixed joints) has rotational inertia of its own.
    A missing <inertia> is I006's on a moving link (S019 reports it on the others)."""
    moving = _moving_links(ctx.model)
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or not (inertial.mass or 0) > 0:
            continue
        element = inertial.first_child("inertia")
        if element is None:
            if in_inert_body and link.name in moving:  # urdfdom refuses it too: on other links that is S019's
                yield Hit(f"link '{link.name}' has mass {inertial.mass:g} kg but no <inertia>", inertial.element)
            continue
        if not finite_tensor(inertial.tensor):
            continue
        if any(inertial.tensor):
            moments = tensor_moments(inertial.tensor)
            if not effectively_zero(moments):
                continue
            what = (f"an effectively zero inertia tensor: principal moments {_fmt(moments)}, all below "
                    f"{EFFECTIVELY_ZERO:g} kg·m²")
        else:
            what = "an all-zero inertia tensor"
        body = ctx.rigid_body(link)
        inert = _inert(body)
        if inert is None or inert != in_inert_body:
            continue  # a body whose numbers are not finite: F007's
        welded = [name for name in body.members if name != link.name]
        if in_inert_body:
            shown = ", ".join(f"'{name}'" for name in welded[:3]) + (", ..." if len(welded) > 3 else "")
            also = f", nor have the links welded to it ({shown})" if welded else ""
            yield Hit(f"link '{link.name}' has mass {inertial.mass:g} kg and {what}{also}", element)
        else:
            joint = ctx.model.parent_joint(link.name)
            where = f" on fixed joint '{joint.name}'" if joint is not None and joint.type == "fixed" else ""
            carrier = max(welded, key=lambda name: _mass(ctx.model.link(name)))
            yield Hit(f"link '{link.name}'{where} has mass {inertial.mass:g} kg and {what}; welded into one body "
                      f"with '{carrier}', whose inertia carries it", element)


def _mass(link) -> float:
    """The link's mass when it is a positive finite number, else 0."""
    mass = link.inertial.mass if link is not None and link.inertial is not None else None
    return mass if mass is not None and math.isfinite(mass) and mass > 0 else 0.0


def _inert(body) -> bool | None:
    """True when a rigid body has no usable rotational inertia (its composite's smallest moment is below
    mjMINVAL, or below 1e-9 of its largest), None when its numbers are not finite."""
    if not all(map(math.isfinite, body.moments)):
        return None
    smallest, largest = body.moments[0], body.moments[-1]
    return not smallest >= max(MJ_MINVAL, NEAR_SINGULAR_RATIO * largest)


_ZERO_TENSOR = '<inertial><mass value="1"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>'


@rule("I006", "inertia-zero", "error", "Zero or missing inertia tensor with positive mass on a moving link",
      engines=("pybullet", "mujoco", "drake", "gazebo"),
      refused_by=("mujoco",),
      breaks="MuJoCo refuses the moving body (moments below mjMINVAL) and PyBullet loaded with "
             "URDF_USE_INERTIA_FROM_FILE divides by the zero moments.",
      why="""A body with mass but no rotational inertia (ixx = iyy = izz = 0, moments below 1e-15 that
      are zero written with rounding noise, or no <inertia>) is a point mass. On a link that moves
      (or on the root, which floats unless fixed by the loader) PyBullet divides by the zero moments
      and the joint accelerations blow up; MuJoCo's URDF import reads an all-zero tensor as
      "not given" and refuses a moving body whose moments are below mjMINVAL. urdfdom refuses an
      <inertial> without <inertia> outright. Engines simulate links welded by fixed joints as one
      body (MuJoCo fuses them, PyBullet's articulated solver carries their inertia together), so a
      zero tensor is reported here only when that whole body has no rotational inertia; a virtual
      root (mass 1e-10, zero tensor) welded to a body with real inertia is I008's, an info (measured:
      stable fixed and floating in PyBullet 3.2.7 and MuJoCo 4.0).""",
      fix="Compute the tensor from the geometry (box: m(y²+z²)/12 ...; ar3cli fix-inertia).",
      bad=arm(link_extra=_ZERO_TENSOR),
      good=arm(), fixed_by="fix-inertia",
      thresholds="Effectively zero: every principal moment below EFFECTIVELY_ZERO = 1e-15 kg·m² (MuJoCo's mjMINVAL); "
                 "the welded body lacks inertia when its composite tensor's smallest moment is below MJ_MINVAL or "
                 "NEAR_SINGULAR_RATIO = 1e-9 of its largest.",
      references="MuJoCo user_model.cc (moving bodies need mass and moments >= mjMINVAL) and xml_urdf.cc (an "
                 "all-zero tensor is undefined); urdfdom link.cpp "
                 "parseInertial (\"Inertial element must have inertia element\").")
def inertia_zero(ctx) -> Iterator[Hit]:
    yield from _zero_tensor_hits(ctx, in_inert_body=True)


@rule("I008", "inertia-zero-fixed-link", "info", "Zero inertia tensor on a link welded to a body that has inertia",
      why="""A link welded by fixed joints to links with real inertia never rotates by itself: every
      engine simulates the welded links as one body (PyBullet and Drake weld it, MuJoCo fuses it), whose
      composite inertia carries the point mass. That covers a sensor frame or flange on a fixed joint,
      and a virtual root (mass 0 or 1e-10) welded to the real base: measured stable fixed and floating
      in PyBullet 3.2.7 and MuJoCo 4.0. Still, the zero tensor is not the part's real inertia, and the
      link becomes a problem the day the joint is made movable. A body with no inertia at all is I006's.""",
      fix="Compute the tensor from the geometry (ar3cli fix-inertia), or drop the mass if the link is a pure frame.",
      bad=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="flange">{_ZERO_TENSOR}</link>
          <joint name="flange_joint" type="fixed"><parent link="base"/><child link="flange"/></joint>"""),
      good=robot(f"""
          <link name="base">{LINK_INERTIAL}</link><link name="flange">{LINK_INERTIAL}</link>
          <joint name="flange_joint" type="fixed"><parent link="base"/><child link="flange"/></joint>"""),
      fixed_by="fix-inertia",
      thresholds="Effectively zero: every principal moment below EFFECTIVELY_ZERO = 1e-15 kg·m². The welded body "
                 "has inertia when its composite tensor (parallel-axis terms included) has every moment at least "
                 "MJ_MINVAL and at least NEAR_SINGULAR_RATIO = 1e-9 of its largest.")
def inertia_zero_fixed_link(ctx) -> Iterator[Hit]:
    yield from _zero_tensor_hits(ctx, in_inert_body=False)


@rule("I009", "inertia-near-singular", "error", "Near-singular inertia tensor on a moving link",
      engines=("mujoco", "pybullet", "drake"),
      refused_by=("mujoco",),
      breaks="MuJoCo refuses the body (a moment below mjMINVAL); every solver that inverts the tensor meets a "
             "condition number above 1e9.",
      why="""A principal moment below MuJoCo's mjMINVAL (1e-15 kg·m²) makes MuJoCo refuse a moving
      body ("mass and inertia of moving bodies must be larger than mjMINVAL"; (2.2e-18, 0.215,
      0.215) is refused). A moment below 1e-9 of the largest belongs to no real body (a rod's ratio
      is 6(r/L)²): it is a typo or lost digits, and it makes the body's inertia ill-conditioned (condition
      number above 1e9) where a solver inverts it: a floating base, a ball joint. Links welded by fixed
      joints to links whose inertia carries them are exempt (engines simulate the welded links as one
      body); tensors that also break A + B >= C are I005's.""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="1"/><inertia ixx="2.2e-18" ixy="0" ixz="0" iyy="0.215" iyz="0" izz="0.215"/></inertial>'),
      good=arm(link_extra='<inertial><mass value="1"/><inertia ixx="1e-4" ixy="0" ixz="0" iyy="0.215" iyz="0" izz="0.215"/></inertial>'),
      fixed_by="fix-inertia",
      thresholds="Smallest principal moment below MJ_MINVAL = 1e-15 kg·m², or below NEAR_SINGULAR_RATIO = 1e-9 "
                 "times the largest, while the largest is at least 1e-15 (else I006/I008).",
      references="MuJoCo include/mujoco/mjtnum.h (mjMINVAL) and src/user/user_model.cc (moving-body check).")
def inertia_near_singular(ctx) -> Iterator[Hit]:
    def ok(inertial, moments) -> bool:
        return not near_singular(moments) or not _triangle_ok(inertial, moments)

    for link, inertial, moments in _tensor_hits(ctx, ok):
        if not (inertial.mass or 0) > 0 or _inert(ctx.rigid_body(link)) is not True:
            continue  # welded to links whose inertia carries it (or numbers that are not finite: F007's)
        smallest, largest = moments[0], moments[-1]
        why = (f"below MuJoCo's mjMINVAL {MJ_MINVAL:g}: MuJoCo refuses the body" if smallest < MJ_MINVAL else
               f"{smallest / largest:.1e} of the largest: no real body is that thin")
        yield Hit(f"link '{link.name}' principal moments {_fmt(moments)}: the smallest is {why}",
                  inertial.first_child("inertia"))


@rule("I007", "inertia-implausible", "warning", "Inertia implausible for the link's geometry",
      why="""The radius of gyration sqrt(I_max / m) of a body is at most the size of the body (about
      its COM it cannot exceed the diagonal of its bounding box). A much larger value means the
      tensor belongs to something else: a placeholder I = 1 on a 0.1 kg link, grams vs kilograms, or
      g·mm² vs kg·m². The link then swings like a body many metres wide. A tensor no body can have
      (I004, I005, I009) is reported there alone. The body's size is the box around all its shapes,
      visual and collision: a part that collides as a placeholder (Baxter's screen, a 1 mm sphere) is
      still as large as it is drawn. When the tensor read in kg·mm² or g·mm² (a CAD
      export's units) gives the robot's typical radius of gyration, the message says so, with the
      value in kg·m².""",
      fix="Recompute the tensor from the geometry and the mass (ar3cli fix-inertia).",
      bad=arm(link_extra='<inertial><mass value="0.1"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'
                         '<collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>'),
      good=arm(link_extra=LINK_INERTIAL + '<collision><geometry><box size="0.3 0.3 0.3"/></geometry></collision>'),
      fixed_by="fix-inertia --include-implausible",
      thresholds="Radius of gyration sqrt(I_max / m) above IMPLAUSIBLE_FACTOR = 3 half-diagonals of the box around the "
                 "link's visual and collision shapes. A unit is named when the tensor / 1e6 (kg·mm²) or / 1e9 "
                 "(g·mm²) gives a ratio within SAME_SHAPE = 5x of the robot's median link ratio and an I_max within "
                 "SOLID_RANGE = 0.05 to 4 times a solid box the size of the geometry; never for a placeholder (a "
                 "diagonal of powers of ten).")
def inertia_implausible(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        found = _gyration_ratio(ctx, link)
        if found is None or found[0] <= IMPLAUSIBLE_FACTOR:
            continue
        ratio, gyration, half_diagonal, largest = found
        unit = tensor_unit(ctx, link)
        looks = (f": the tensor looks like {unit[0]} (I_max {largest / unit[1]:.3g} kg·m²?)" if unit is not None else "")
        yield Hit(f"link '{link.name}' radius of gyration {gyration:.3g} m is {ratio:.0f}x "
                  f"its geometry's half-diagonal {half_diagonal:.3g} m (mass {link.inertial.mass:g} kg, "
                  f"I_max {largest:.3g} kg·m²){looks}", link.inertial.first_child("inertia"),
                  hint=(f"Divide every inertia entry by {unit[1]:.0e} (kg·m²), or recompute it: ar3cli fix-inertia "
                        "rescales it." if unit is not None else None))


def _gyration_ratio(ctx, link, mass: float | None = None) -> tuple[float, float, float, float] | None:
    """(radius of gyration / the half-diagonal of the link's geometry box, the radius of gyration
    sqrt(I_max / m), the half-diagonal, I_max) of a valid tensor, with the file's mass (or ``mass``);
    None when there is nothing to compare. Once per link, mass and file."""
    known = ctx.link_memo("gyration-ratios")
    key = (id(link), mass)
    if key not in known:
        known[key] = _gyration(ctx, link, mass)
    return known[key]


def _gyration(ctx, link, mass: float | None) -> tuple[float, float, float, float] | None:
    inertial = link.inertial
    mass = mass if mass is not None else (inertial.mass if inertial is not None else None)
    if inertial is None or not finite_tensor(inertial.tensor) or mass is None or not mass > 0 \
            or not math.isfinite(mass):
        return None
    bounds = ctx.body_bounds(link)
    if bounds is None:
        return None
    half_diagonal = 0.5 * math.dist(bounds[0], bounds[1])
    moments = tensor_moments(inertial.tensor)
    if half_diagonal <= 0 or moments[-1] <= 0 or not _valid_body(inertial, moments):
        return None  # a tensor no body has is I004's, I005's or I009's: one cause, one finding
    gyration = math.sqrt(moments[-1] / mass)
    return gyration / half_diagonal, gyration, half_diagonal, moments[-1]


TENSOR_UNITS = (("kg·mm²", 1e6), ("g·mm²", 1e9))
"""Units a CAD export writes tensors in, and how many of them make a kg·m² (I007)."""
SAME_SHAPE = 5.0
"""A tensor taken in another unit must give a radius of gyration within this factor of the robot's
typical link (relative to each link's own size) to be said to be in that unit."""


SOLID_RANGE = (0.05, 4.0)
"""... and an I_max within this range of a solid box's the size of the link's geometry (a part fills part of
its box; a thin shell about its COM reaches a few times the solid box)."""


def _placeholder_tensor(tensor) -> bool:
    """A diagonal tensor of powers of ten (I = 1; pr2's sensor frames' 1e-4, 1e-6, 1e-4): a placeholder
    someone typed, not a CAD export in another unit."""
    ixx, ixy, ixz, iyy, iyz, izz = tensor
    if ixy or ixz or iyz or not min(ixx, iyy, izz) > 0:
        return False
    return all(abs(math.log10(value) - round(math.log10(value))) < 1e-9 for value in (ixx, iyy, izz))


def typical_gyration(ctx) -> float:
    """The median, over the robot's links with a plausible tensor, of radius of gyration / half-diagonal
    (how its parts fill their boxes); 0.5 (a solid part) when no link has one."""
    def build(_model) -> float:
        ratios = sorted(found[0] for link in ctx.model.links
                        if (found := _gyration_ratio(ctx, link)) is not None and found[0] <= IMPLAUSIBLE_FACTOR)
        return ratios[len(ratios) // 2] if ratios else 0.5
    return ctx.shared("typical-gyration", build)


def tensor_unit(ctx, link) -> tuple[str, float] | None:
    """(unit, kg·m² divisor) when the link's tensor looks written in kg·mm² or g·mm² (x1e6, x1e9): taken in
    that unit, its radius of gyration, with the link's mass in kg (read as grams when I013 says so), is
    plausible and within SAME_SHAPE of the robot's typical link, and its I_max within SOLID_RANGE of a solid
    box the size of the link's geometry; the closest such unit. A placeholder (I = 1) is no unit. None
    otherwise."""
    mass = grams_evidence(ctx, link)
    found = _gyration_ratio(ctx, link, mass)
    if found is None or found[0] <= IMPLAUSIBLE_FACTOR or _placeholder_tensor(link.inertial.tensor):
        return None
    mass = mass or link.inertial.mass
    box = ctx.body_bounds(link)
    extents = sorted(hi - lo for lo, hi in zip(*box))
    solid = mass * (extents[1] ** 2 + extents[2] ** 2) / 12  # I_max of a solid box the size of the geometry
    typical = typical_gyration(ctx)
    best = None
    for unit, divisor in TENSOR_UNITS:
        converted = found[0] / math.sqrt(divisor)
        if converted <= IMPLAUSIBLE_FACTOR and typical / SAME_SHAPE <= converted <= typical * SAME_SHAPE \
                and SOLID_RANGE[0] * solid <= found[3] / divisor <= SOLID_RANGE[1] * solid:
            miss = abs(math.log(converted / typical))
            if best is None or miss < best[0]:
                best = (miss, unit, divisor)
    return None if best is None else (best[1], best[2])


@rule("I010", "mass-zero-with-inertia", "info", "Mass 0 with a non-zero inertia tensor",
      engines=("drake",),
      why="""mass 0 with a non-zero tensor contradicts itself. PyBullet reads it as the author
      meant: a mass-0 root is static (its idiom for tables and planes) and a mass-0 link on a fixed
      joint adds nothing; MuJoCo's URDF import fixes the root to the world and merges fixed links,
      so it agrees. Drake does not: it cannot re-express the
      tensor about the centre of mass (it divides by the mass), warns, and substitutes a 1 kg sphere
      of water density, so the static object falls and a tool flange adds a kilogram to the arm. On a
      moving link mass 0 is I003's; the reverse, a positive mass with a zero tensor, is I006/I008.""",
      fix="Decide which is true: give the real mass, or set the tensor to zero as well (a massless frame or a "
          "static object).",
      bad=robot('''<link name="table"><inertial><mass value="0"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
          <collision><geometry><box size="1 1 0.1"/></geometry></collision></link>'''),
      good=robot('''<link name="table"><inertial><mass value="0"/><inertia ixx="0" ixy="0" ixz="0" iyy="0" iyz="0" izz="0"/></inertial>
          <collision><geometry><box size="1 1 0.1"/></geometry></collision></link>'''),
      references="Drake multibody/parsing/detail_common.cc ParseSpatialInertia (\"While re-expressing as central "
                 "inertia\": plausible sphere substituted).")
def mass_zero_with_inertia(ctx) -> Iterator[Hit]:
    moving = _moving_links(ctx.model)
    for link in ctx.model.links:
        inertial = link.inertial
        if inertial is None or link.name in moving or inertial.mass != 0 or link.name == "world" \
                or not finite_tensor(inertial.tensor) or effectively_zero(tensor_moments(inertial.tensor)):
            continue
        effect = ("PyBullet adds nothing to the parent" if ctx.model.parent_joint(link.name) is not None
                  else "a static body in PyBullet")
        yield Hit(f"link '{link.name}' has mass 0 but inertia {_fmt(tensor_moments(inertial.tensor))}: {effect}, "
                  "a 1 kg sphere in Drake", inertial.first_child("mass"))


@rule("I011", "world-inertial", "warning", "<inertial> on the link named 'world'",
      engines=("drake", "ros", "pybullet"),
      why="""A link named "world" is the world itself in Drake, MuJoCo and Gazebo, not a body:
      Drake ignores its <inertial> with a warning, KDL (robot_state_publisher, MoveIt) cannot give
      the root link an inertia and ignores it too. PyBullet alone uses it: with useFixedBase=False the
      "world" becomes a floating body of that mass. The file means different robots in different
      tools.""",
      fix="Remove the <inertial> from the world link; put the mass on the robot's first real link.",
      bad=robot(f'''<link name="world">{LINK_INERTIAL}</link><link name="base">{LINK_INERTIAL}</link>
          <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>'''),
      good=robot(f'''<link name="world"/><link name="base">{LINK_INERTIAL}</link>
          <joint name="fix" type="fixed"><parent link="world"/><child link="base"/></joint>'''),
      references="Drake multibody/parsing/detail_urdf_parser.cc ParseBody (\"The <inertial> tag is being "
                 "ignored\"); kdl_parser (\"KDL does not support a root link with an inertia\").")
def world_inertial(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        if link.name == "world" and link.inertial is not None:
            yield Hit("link 'world' has an <inertial>: Drake and KDL ignore it, PyBullet makes it a body",
                      link.inertial.element)


def _welded_to_root(ctx, link) -> bool:
    """Whether ``link`` is welded (fixed joints only) to a root link: part of the base, static when the robot is
    loaded with a fixed base, so its phantom kilogram matters only if the robot floats (I012's, at info)."""
    return ctx.model.parent_joint(ctx.rigid_body(link).top) is None


@rule("I012", "root-inertial-missing", "info", "Root link with geometry but no <inertial>",
      engines=("pybullet", "drake"),
      why="""This matters only if the robot floats (a mobile base, a legged robot, an object to
      grasp); most arms are loaded with a fixed base and can ignore it. Loaded with
      useFixedBase=False, PyBullet gives a root without <inertial> 1 kg and I = (1, 1, 1), silently
      apart from a C-level warning; Drake makes it a massless free body, whose dynamics are
      singular. (MuJoCo's URDF import fixes the root to the world whatever its mass.)
      A root without geometry weighs 1 kg in PyBullet too (only one named world gets 0): a frame fixed
      on top of a body (base_footprint, Jackal's base_link over its chassis) is reported, as the body
      under it is most likely a mobile base; a frame an arm turns on (a moving joint) is not. Links welded to the root by fixed joints belong to the same body: those
      without <inertial> add PyBullet's 1 kg each to it when it floats, and nothing when it is fixed, so
      they are listed here (one finding for the base) rather than as I002 warnings.""",
      fix="If the robot floats, give the root link its real <inertial> (ar3cli fix-inertia --links ROOT computes one "
          "from the geometry) and the frames welded to it a tiny one; if it is always fixed to the world, nothing to "
          "do.",
      bad=robot('''<link name="chassis"><collision><geometry><box size="0.5 0.3 0.1"/></geometry></collision></link>'''),
      good=robot(f'''<link name="chassis">{LINK_INERTIAL}<collision><geometry><box size="0.5 0.3 0.1"/></geometry></collision></link>'''),
      thresholds="Skipped: a root named world (PyBullet gives it no mass; nor its welded links), and a root without "
                 "geometry that is not joined to the rest by fixed joints only (an arm's mounting frame).",
      references="PyBullet UrdfParser.cpp parseLink (mass 1, inertia 1 without <inertial>); Drake "
                 "multibody/parsing/detail_urdf_parser.cc ParseBody (no <inertial>: zero spatial inertia).")
def root_inertial_missing(ctx) -> Iterator[Hit]:
    roots = ctx.model.root_links()
    if len(roots) != 1:
        return  # no root or several: S005's business
    root = roots[0]
    if root.name == "world":
        return  # PyBullet's only mass-0 default: a static base, with whatever is welded to it
    welded = [ctx.model.link(name) for name in ctx.rigid_body(root).members if name not in (root.name, "world")
              and ctx.model.link(name).inertial is None]
    names = ", ".join(f"'{link.name}'" for link in welded[:3]) + (", ..." if len(welded) > 3 else "")
    they = _plural(len(welded), "link")
    also = f", nor {'do' if len(welded) > 1 else 'does'} the {they} welded to it ({names})" if welded else ""
    gets = f"PyBullet gives {'each' if welded else 'it'} 1 kg and I = 1, Drake no mass at all"
    below = [joint.type for joint in ctx.model.joints if joint.parent == root.name]
    if root.inertial is None and root.has_geometry:
        yield Hit(f"root link '{root.name}' has geometry but no <inertial>{also}: if this robot floats, {gets}",
                  root.element, hint=_floating_fix(ctx, [root, *welded]))
    elif root.inertial is None and below and all(kind == "fixed" for kind in below):
        yield Hit(f"root link '{root.name}' is a frame (no geometry) with no <inertial>{also}, on top of a body: "
                  f"if this robot floats, {gets}", root.element, hint=_floating_fix(ctx, [root, *welded]))
    elif welded:
        yield Hit(f"{they} welded to root link '{root.name}' {'have' if len(welded) > 1 else 'has'} no <inertial> "
                  f"({names}): if this robot floats, PyBullet adds 1 kg and I = 1 for {'each' if len(welded) > 1 else 'it'} "
                  "to its base", root.element, hint=_floating_fix(ctx, welded))


def _plural(count: int, noun: str) -> str:
    return f"{count} {noun}{'s' if count != 1 else ''}"


def _floating_fix(ctx, links) -> str:
    """I012's hint, for a robot that floats: fix-inertia with a density for the parts with geometry, without
    one for the frames welded below (it gives them a tiny inertial), and a tiny inertial written by hand for a
    root frame (fix-inertia computes nothing for a link without geometry or a fixed joint above it)."""
    parts = [link.name for link in links if link.has_geometry]
    welded_frames = [link.name for link in links if not link.has_geometry and ctx.model.parent_joint(link.name)]
    root_frames = [link.name for link in links if not link.has_geometry and not ctx.model.parent_joint(link.name)]
    commands = []
    if parts:  # one command: the frames among them get a tiny inertial whatever the density
        commands.append(f"ar3cli fix-inertia --links {','.join(parts + welded_frames)} --density KG_PER_M3 (or "
                        "write the real <inertial>)")
    elif welded_frames:
        commands.append(f"ar3cli fix-inertia --links {','.join(welded_frames)} (a tiny <inertial> for each frame)")
    if root_frames:
        commands.append(f"give '{root_frames[0]}' a tiny <inertial> (mass 1e-6 kg, I = 1e-12)")
    return f"If the robot floats: {'; '.join(commands)}; a fixed-base robot can ignore this."


FIXED_BY_FIX_INERTIA = (inertial_missing, fixed_link_inertial_missing, mass_not_positive, inertia_not_positive_definite,
         inertia_triangle, inertia_zero, inertia_zero_fixed_link, inertia_near_singular, inertia_implausible)
"""The rules whose links fix-inertia recomputes (:func:`ar3cli.fix.inertia_plan.links_needing_inertia`),
in its order of reasons: I007 last, so a link reported as I007 has nothing invalid."""
RESCALED_BY_FIX_INERTIA = (density_implausible,)
"""Rules fix-inertia answers by rescaling the file's own numbers where their unit is plain (a mass in grams,
I013; I007's tensors in kg·mm² or g·mm² too): :func:`unit_mistakes`."""
NOT_FIXED_BY_FIX_INERTIA = (mass_zero_with_inertia, world_inertial, root_inertial_missing,
                            translating_frame_inertial_missing)
"""Inertia findings fix-inertia leaves alone: the fix is a decision only the author can make."""


def unit_mistakes(ctx) -> dict[str, tuple[float, float, str]]:
    """Link name -> (mass divisor, tensor divisor, why) for the links whose mass (I013) or tensor (I007) the
    rules say is in another unit: a mass in grams (/ 1000; its tensor with it when, read with the gram
    mass, the tensor is a plausible body's) and a tensor in kg·mm² or g·mm². fix-inertia rescales them."""
    found: dict[str, tuple[float, float, str]] = {}
    for link in ctx.model.links:
        grams = grams_evidence(ctx, link)
        unit = tensor_unit(ctx, link)
        if grams is None and unit is None:
            continue
        reasons, mass_divisor, tensor_divisor = [], 1.0, 1.0
        if grams is not None:
            mass_divisor = link.inertial.mass / grams
            reasons.append(f"I013: mass {link.inertial.mass:g} in grams, / 1000")
            plain = _gyration_ratio(ctx, link)
            if unit is None and plain is not None and plain[0] <= IMPLAUSIBLE_FACTOR:
                tensor_divisor = mass_divisor  # the tensor was written for the gram mass: in g·m²
                reasons.append("tensor in g·m² with it, / 1000")
        if unit is not None:
            tensor_divisor = unit[1]
            reasons.append(f"I007: tensor in {unit[0]}, / {unit[1]:.0e}")
        found[link.name] = (mass_divisor, tensor_divisor, "; ".join(reasons))
    return found
