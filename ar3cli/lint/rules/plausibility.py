"""Plausibility rules (I013-I015): masses no material, part or solver can live with.

Every number is a bound that holds whatever the shapes' overlap: the collision volume of a link is at
least its largest closed shape and at most the sum of its shapes' boxes, so "too light" is judged on
primitives alone (exact volumes) and "too dense" on boxes (an upper bound on any mesh's volume).
"""

from __future__ import annotations

import math
from collections.abc import Iterator

from ar3cli.lint.rules.base import Hit, arm, robot, rule

MIN_DENSITY = 50.0
"""kg/m³: lighter than rigid foam (expanded polystyrene is 15-30, but no robot part is made of it
whole); a link this light for its closed collision primitive is a mass in grams, a size in mm, or a
hollow shell modelled as a solid box."""
MAX_DENSITY = 25_000.0
"""kg/m³: denser than osmium (22,590), the densest element: no part can be."""
MIN_MASS = 1e-3
"""kg: a moving link lighter than a gram (I003 reports 0 and less)."""
MAX_MASS_RATIO = 1000.0
"""Heavier over lighter link across a moving joint."""


DENSITY_MIN_MASS = 0.05
"""kg: lighter links are placeholders (sensor frames at 0.01 kg, contact points at 1e-6 kg), not judged."""
DENSITY_MIN_SIZE = 0.02
"""m: shapes whose box diagonal is below this are contact points or markers, not the part's volume."""


def rigid_masses(model) -> dict[str, float]:
    """Link name -> the mass of its rigid group (links welded by fixed joints move as one body: MuJoCo,
    Drake and Isaac merge them, and the solver sees their sum). Links with a missing or non-finite mass
    count as 0. Linear: a union-find over the fixed joints."""
    parent: dict[str, str] = {}

    def find(name: str) -> str:
        while parent.get(name, name) != name:
            parent[name] = parent.get(parent[name], parent[name])
            name = parent[name]
        return name

    for joint in model.joints:
        if joint.type == "fixed" and joint.parent and joint.child:
            a, b = find(joint.parent), find(joint.child)
            if a != b:
                parent[b] = a
    totals: dict[str, float] = {}
    for link in model.links:
        mass = link.inertial.mass if link.inertial is not None else None
        root = find(link.name)
        totals[root] = totals.get(root, 0.0) + (mass if mass is not None and math.isfinite(mass) and mass > 0 else 0.0)
    return {link.name: totals[find(link.name)] for link in model.links}


def subtree_masses(model) -> dict[str, float]:
    """Link name -> the mass of the link and everything below it (what its parent joint moves): the
    joint-space inertia a joint sees is that of its whole subtree, so a light link between two joints
    of a finger is carried by the finger below it. Masses as in :func:`rigid_masses`. Linear: links in
    breadth-first order from the roots, then each one's total added to its parent's, deepest first (a
    link reached twice, or in a loop no root reaches, counts its own mass only: S006's business)."""
    totals = {link.name: (mass if (mass := link.inertial.mass if link.inertial is not None else None) is not None
                          and math.isfinite(mass) and mass > 0 else 0.0) for link in model.links}
    order = [link.name for link in model.root_links()]
    seen = set(order)
    for name in order:  # grows while it is walked: breadth-first
        for joint in model.child_joints(name):
            if joint.child in totals and joint.child not in seen:
                seen.add(joint.child)
                order.append(joint.child)
    for name in reversed(order):
        joint = model.parent_joint(name)
        if joint is not None and joint.parent in seen and joint.parent != name:
            totals[joint.parent] += totals[name]
    return totals


def _primitive_volume(shape) -> float | None:
    """Exact volume of a box, cylinder, sphere or capsule (m³), None for meshes and unknown shapes."""
    kind, params = shape.geometry.kind, shape.geometry.params
    try:
        if kind == "box" and params.get("size"):
            x, y, z = (abs(float(v)) for v in params["size"])
            return x * y * z
        if kind in ("cylinder", "capsule"):
            r, length = abs(params["radius"]), abs(params["length"])
            return math.pi * r * r * length + (4 / 3 * math.pi * r ** 3 if kind == "capsule" else 0.0)
        if kind == "sphere":
            return 4 / 3 * math.pi * abs(params["radius"]) ** 3
    except (KeyError, TypeError, ValueError, OverflowError):  # OverflowError: radius="1e200" cubed
        return None
    return None


def _box_volume(ctx, shape) -> float | None:
    box = ctx.shape_bounds(shape)
    if box is None:
        return None
    return math.prod(hi - lo for lo, hi in zip(*box))


def density_bounds(ctx, link) -> tuple[float | None, float | None]:
    """(highest possible density, lowest possible density) in kg/m³ from the link's collision shapes;
    each None when the shapes cannot bound it. Once per link and file (I013, its grams evidence and the
    robot's typical density all ask)."""
    known = ctx.link_memo("density-bounds")
    if id(link) not in known:  # the model, and with it every link, lives as long as the context
        known[id(link)] = _density_bounds(ctx, link)
    return known[id(link)]


def _density_bounds(ctx, link) -> tuple[float | None, float | None]:
    mass = link.inertial.mass if link.inertial is not None else None
    if mass is None or not mass >= DENSITY_MIN_MASS or not math.isfinite(mass) or not link.collisions:
        return None, None
    exact = [_primitive_volume(shape) for shape in link.collisions]
    largest = max((v for v in exact if v and v ** (1 / 3) * math.sqrt(3) >= DENSITY_MIN_SIZE), default=0.0)
    highest = mass / largest if largest > 0 else None
    volumes = []
    for shapes in (link.collisions, link.visuals):  # the drawn part may be the real one (contact spheres)
        if not shapes:
            continue  # no visual: the collision shapes alone bound the volume
        boxes = [_box_volume(ctx, shape) for shape in shapes]
        if not boxes or not all(v is not None and v > 0 for v in boxes):
            return highest, None  # a shape of unknown or flat size: no upper bound on the volume
        volumes.append(sum(boxes))  # type: ignore[arg-type]
    lowest = mass / max(volumes)
    return highest, lowest


GRAMS = 1000.0
"""Grams per kilogram: a mass typed in grams is this many times too large."""
SAME_MATERIAL = 10.0
"""A link whose mass, taken as grams, gives a density within this factor of the robot's typical link is
made of what the rest is made of: the mass was typed in grams (I013). The factor spans plastic to steel
(1,200 to 7,850 kg/m³) and, roughly, how much of its box a part fills."""


def typical_density(ctx) -> float | None:
    """The robot's typical link density (kg/m³): the median of the lowest possible densities
    (:func:`density_bounds`) of its links that some material has; None when no link has one (a robot
    written in grams throughout)."""
    def build(_model) -> float | None:
        lows = sorted(low for link in ctx.model.links
                      if (low := density_bounds(ctx, link)[1]) is not None and low <= MAX_DENSITY)
        return lows[len(lows) // 2] if lows else None
    return ctx.shared("typical-density", build)


def grams_evidence(ctx, link) -> float | None:
    """The link's mass in kg when it was typed in grams: divided by 1000, its lowest possible density is a
    material's and within SAME_MATERIAL of the robot's typical link (:func:`typical_density`; a robot with no
    plausible link is judged on materials alone, and then only a density no material has says grams), and
    the part still weighs a gram at least (a 0.1 kg tool frame in a 1 cm box is a lumped placeholder, not
    0.1 g). None otherwise. A bicycle frame's box is mostly air: 1 kg in it is 0.3 kg/m³, and typed in grams
    it is still a material's density; only the robot's other links show it is 1000 times theirs."""
    highest, lowest = density_bounds(ctx, link)
    if lowest is None or not link.inertial.mass / GRAMS >= MIN_MASS:
        return None
    low, high = lowest / GRAMS, (highest / GRAMS if highest is not None else None)
    if low > MAX_DENSITY or (high is not None and high < MIN_DENSITY):
        return None
    typical = typical_density(ctx)
    if typical is None:  # nothing to compare with: only a density no material has says grams
        return link.inertial.mass / GRAMS if lowest > MAX_DENSITY else None
    return link.inertial.mass / GRAMS if typical / SAME_MATERIAL <= low <= typical * SAME_MATERIAL else None


def _dense(mass: str, size: str = "0.1 0.1 0.1") -> str:
    return robot(f"""
        <link name="base"><inertial><mass value="{mass}"/><inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial>
          <collision><geometry><box size="{size}"/></geometry></collision></link>""")


@rule("I013", "density-implausible", "warning", "Link density no material has",
      why="""Mass over the volume of the link's collision geometry is a density; outside what materials
      allow, the mass or the geometry is wrong: a mass in grams or a size in millimetres, a hollow cover
      modelled as a solid box, a copied <mass>. Contact and gravity forces then disagree with the shape
      the simulator collides with. A link whose mass, read as grams, gives the density of the
      robot's other links (it is about 1000 times theirs, whether or not a material could be that
      dense) is said to be in grams, with the value in kilograms.""",
      fix="Check the <mass value> (kg) and the collision sizes (m); compute the mass from the real part's density.",
      bad=_dense("1", "0.5 0.5 0.5"), good=_dense("2.7"),
      thresholds=f"Reported below {MIN_DENSITY:g} kg/m³ (on the largest collision primitive alone, so overlapping "
                 f"shapes never make a link look light; meshes are not used, their closed volume is unknown "
                 f"without reading their triangles) or above {MAX_DENSITY:,.0f} kg/m³ (osmium is 22,590; judged on the "
                 "sum of the collision (or, when larger, the visual) shapes' boxes, an upper bound on any volume, meshes "
                 f"included). Links under {DENSITY_MIN_MASS:g} kg and primitives under {DENSITY_MIN_SIZE} m across are "
                 f"placeholders and contact points, not judged. Grams: the mass / 1000 gives a density within "
                 f"materials and within SAME_MATERIAL = {SAME_MATERIAL:g}x of the robot's median link.",
      fixed_by="fix-inertia (a mass in grams)",
      references="CRC Handbook of Chemistry and Physics (osmium 22.59 g/cm³); simcheck 0.2.0 (density).")
def density_implausible(ctx) -> Iterator[Hit]:
    for link in ctx.model.links:
        highest, lowest = density_bounds(ctx, link)
        if lowest is not None and lowest <= MAX_DENSITY and (grams := grams_evidence(ctx, link)) is not None:
            yield Hit(f"link '{link.name}' is at least {lowest:.4g} kg/m³ ({link.inertial.mass:g} kg in its collision "
                      f"shapes), about 1000 times the robot's other links ({typical_density(ctx):.3g} kg/m³): the mass "
                      f"looks like grams ({grams:.6g} kg?)", _mass_element(link),
                      hint=f'Write <mass value="{grams:.6g}"/> (kilograms), and check the tensor\'s unit; ar3cli '
                           "fix-inertia rescales it.")
        elif highest is not None and highest < MIN_DENSITY:
            yield Hit(f"link '{link.name}' is at most {highest:.3g} kg/m³ ({link.inertial.mass:g} kg in its collision "
                      f"shapes): lighter than any solid material", _mass_element(link))
        elif lowest is not None and lowest > MAX_DENSITY:
            grams = grams_evidence(ctx, link)
            unit = (f"; the mass looks like grams ({grams:.6g} kg?, at least {lowest / GRAMS:.4g} kg/m³ then, like the "
                    "robot's other links)" if grams is not None else "")
            yield Hit(f"link '{link.name}' is at least {lowest:.4g} kg/m³ ({link.inertial.mass:g} kg in its collision "
                      f"shapes): denser than any material{unit}", _mass_element(link),
                      hint=f'Write <mass value="{grams:.6g}"/> (kilograms), and check the tensor\'s unit; ar3cli '
                           "fix-inertia rescales it." if grams is not None else None)


def _mass_element(link):
    """The link's ``<mass>`` element (where a density finding points), or None."""
    return link.inertial.first_child("mass") if link.inertial is not None else None


@rule("I014", "mass-tiny", "warning", "Moving link lighter than a gram",
      why="""A moving link of less than a gram next to kilogram links makes the joint-space inertia
      matrix ill-conditioned: PyBullet and MuJoCo then need tiny time steps, and the joint
      accelerations of that link jitter or blow up. Real moving parts weigh grams at least; a link
      this light is usually a frame that should hang from a fixed joint, or a mass in the wrong unit.
      What a joint moves is its whole subtree: a light link between two joints (the cross of a
      universal joint in a finger) is carried by the links below it and is not reported.""",
      fix="Give the link its real mass, or attach a frame-only link with a fixed joint.",
      bad=arm(link_extra='<inertial><mass value="0.00001"/><inertia ixx="1e-9" ixy="0" ixz="0" iyy="1e-9" iyz="0" izz="1e-9"/></inertial>'),
      good=arm(),
      thresholds=f"Moving links (revolute, continuous, prismatic, planar, floating, spherical) whose subtree (the link "
                 f"and every link below it) weighs more than 0 and less than {MIN_MASS:g} kg.",
      references="MuJoCo documentation, Computation (ill-conditioned mass matrices need smaller timesteps).")
def mass_tiny(ctx) -> Iterator[Hit]:
    moving = {joint.child: joint for joint in ctx.model.joints if joint.moves and joint.child}
    carried = subtree_masses(ctx.model)
    for link in ctx.model.links:
        mass = link.inertial.mass if link.inertial is not None else None
        if link.name in moving and mass is not None and mass > 0 and 0 < carried[link.name] < MIN_MASS:
            yield Hit(f"link '{link.name}' moves (joint '{moving[link.name].name}') and weighs {carried[link.name]:g} kg "
                      "with everything below it", link.inertial.first_child("mass"))


@rule("I015", "mass-ratio", "warning", "Masses across a joint differ more than solvers handle",
      why="""Iterative solvers converge slowly when the bodies a joint connects differ hugely in mass
      (PhysX and Unity advise keeping connected masses within 1:10; maximal-coordinate engines drift
      and jitter). Reduced-coordinate engines (PyBullet's multibody, MuJoCo, Drake) tolerate far more,
      so only ratios beyond 1000:1 are reported: at that point even they need small time steps, and
      the light link is usually a frame that should be fixed or a mass in the wrong unit. What a joint
      moves is its child and everything below it, and that is the side judged: a light parent is a link
      between two moving joints (the virtual links of a planar base, biped2d's x/z sliders), carried on
      both sides, or a root, static when the robot is fixed.""",
      fix="Check both masses (kg); merge a frame-only link into its parent with a fixed joint.",
      bad=arm(link_extra='<inertial><mass value="0.002"/><inertia ixx="1e-7" ixy="0" ixz="0" iyy="1e-7" iyz="0" izz="1e-7"/></inertial>',
              base_extra='<inertial><mass value="50"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>'),
      good=arm(base_extra='<inertial><mass value="5"/><inertia ixx="0.1" ixy="0" ixz="0" iyy="0.1" iyz="0" izz="0.1"/></inertial>'),
      thresholds=f"Parent side / child side above {MAX_MASS_RATIO:g} across a moving joint, the parent side's mass "
                 f"being its rigid group's (links welded by fixed joints), the child side's its subtree's (what the "
                 f"joint moves); a child side lighter than {MIN_MASS:g} kg is I014's alone.",
      references="Unity Manual, Joint and Ragdoll stability (PhysX: mass ratios below 10); MuJoCo documentation, "
                 "Computation.")
def mass_ratio(ctx) -> Iterator[Hit]:
    model = ctx.model
    group = rigid_masses(model)
    carried = subtree_masses(model)
    for joint in model.joints:
        if not joint.moves or joint.parent not in group or joint.child not in group:
            continue
        masses = [group[joint.parent], carried[joint.child]]
        if not all(m > 0 for m in masses):
            continue
        light, heavy = min(masses), max(masses)  # type: ignore[type-var]
        if masses[0] < masses[1]:
            continue  # the light side holds what the joint moves: a link between two joints, or a root (static when fixed)
        if light >= MIN_MASS and heavy / light > MAX_MASS_RATIO:
            yield Hit(f"joint '{joint.name}' connects {masses[0]:g} kg ('{joint.parent}' and what is welded to it) and "
                      f"{masses[1]:g} kg "
                      f"('{joint.child}' and what it carries): ratio {heavy / light:.0f}:1", joint.element)
