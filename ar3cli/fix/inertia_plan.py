"""The fix-inertia fixer: choose links, pick each link's mass source, write new ``<inertial>``s.

Numbers in another unit, by default: a mass the linter says is in grams (I013: too dense, and in
kilograms the density of the robot's other links) is divided by 1000, a tensor it says is in kg·mm² or
g·mm² (I007) by 1e6 or 1e9: the file's own values in SI, centre of mass and axes kept.

Which links, by default: those the lint inertia rules flag as **invalid** (no ``<inertial>``,
mass <= 0, tensor not positive definite, A + B < C, all-zero tensor). A link flagged only as
**implausible** (I007: a valid tensor too large for the geometry) is often a hand-tuned value or a
deliberate placeholder; it is left alone and reported, unless ``--include-implausible`` (or a
``--mass`` for that link) asks for it. ``--links`` and ``--all`` choose by hand.

Mass source, always explicit (first that applies): ``--mass LINK=KG``; a valid (finite, > 0)
mass already in the file; ``--density``; ``--total-mass`` (the robot's total: the masses kept
above are subtracted and the rest is spread over the remaining links with collision geometry, in
proportion to its volume). A link with visual geometry only gets no share of ``--total-mass``: a
visual-only link is a marker or decoration (an end-effector sphere, a sensor frustum), not a
physical part, and its volume says nothing about the robot's mass (one such sphere took a third of
a mobile base's mass). The output names the links that got a share and those left out, and why.
A link without any mass source is reported and left alone.

The centre of mass and tensor always come from the geometry (collision, else visual): the
tensor is only right about the COM it was computed about. Frame links (no geometry, fixed
joint) get ``FRAME_LINK_MASS`` / ``FRAME_LINK_INERTIA``; docs/commands/fix-inertia.md has the
PyBullet measurement behind that choice.
"""

from __future__ import annotations

import math
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING

from ar3cli.errors import UserError
from ar3cli.findings import listed
from ar3cli.fix.driver import Change, Fixer, FixPlan, Skipped, number, same_numbers
from ar3cli.fix.settings import setting
from ar3cli.urdf.edits import Document

if TYPE_CHECKING:  # numpy, the geometry and the lint rules are imported when a plan runs, not for --help
    import numpy as np

    from ar3cli.fix import geometry_mass as inertia
    from ar3cli.maths import mass_properties as mp
    from ar3cli.urdf.model import Model

TENSOR_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")
IMPLAUSIBLE_CODES = frozenset({"I007"})
"""Lint codes that flag a valid but implausible ``<inertial>`` (``inertia_implausible``): recomputed only
on request."""
INCLUDE_IMPLAUSIBLE = "--include-implausible"


SMALLEST_MASS = 1e-9
"""A microgram: below it, masses and inertias are round-off, not a robot (``--mass`` and ``--total-mass``;
``--mass arm=1e-320`` wrote inertias of 1e-323, subnormal numbers)."""
DENSITY_RANGE = (0.01, 1e6)
"""Densities that are a material, in kg/m^3: expanded foams and aerogels start near 1, osmium is
22,590; the margins take units slips the user meant. Outside it the inertia written is no
physics (``--density 1e-320`` gave masses of 1e-323 kg, subnormal numbers that underflow to 0)."""


@dataclass
class InertiaOptions:
    """fix-inertia's own options (each :func:`~ar3cli.fix.settings.setting` is one), checked, and
    the link names and masses they give."""

    links: str | None = setting("--links", default=None, help="Comma-separated links to recompute "
                                "(default: the links the linter flags as invalid).")
    all_links: bool = setting("--all", default=False, help="Recompute every link that has geometry.")
    include_implausible: bool = setting(
        INCLUDE_IMPLAUSIBLE, default=False,
        help="Also recompute links whose inertia is valid but implausible for their geometry (I007: "
             "often a hand-tuned value or a deliberate placeholder). By default they are left alone "
             "and listed.")
    density: float | None = setting("--density", metavar="KG_PER_M3", default=None,
                                    help="Density for links without a valid mass.")
    mass: list[str] | None = setting("--mass", metavar="LINK=KG", default=None,
                                     help="Mass of one link (repeatable); overrides the file.")
    total_mass: float | None = setting("--total-mass", metavar="KG", default=None,
                                       help="The robot's total mass: what the known masses leave "
                                            "is spread over links without one, by volume.")
    link_names: list[str] | None = field(default=None, init=False)
    """``--links`` split at its commas."""
    masses: dict[str, float] = field(default_factory=dict, init=False)
    """``--mass`` as link -> kg."""

    def __post_init__(self) -> None:
        low, high = DENSITY_RANGE
        if self.density is not None and not low <= self.density <= high:
            raise UserError(f"--density {self.density}: must be a density between {low:g} and {high:g} kg/m^3 "
                            f"(e.g. 1200 for PLA, 2700 for aluminium, 7850 for steel)")
        if self.total_mass is not None and not SMALLEST_MASS <= self.total_mass < math.inf:
            raise UserError(f"--total-mass {self.total_mass}: must be a mass of at least {SMALLEST_MASS:g} kg")
        if self.links is not None and self.all_links:
            raise UserError("--links and --all exclude each other")
        if self.include_implausible and (self.links is not None or self.all_links):
            raise UserError("--include-implausible widens the default selection; --links and --all already "
                            "choose the links")
        if self.links is not None:
            self.link_names = [name.strip() for name in self.links.split(",") if name.strip()]
        self.masses = parse_masses(self.mass)


@dataclass
class LeftAlone:
    """A flagged link the default selection does not touch (valid but implausible inertia)."""

    link: str
    element: str
    line: int
    code: str
    reason: str


@dataclass
class _Target:
    link: object
    reason: str
    geometry: inertia.GeometryMass | None = None
    mass: float | None = None
    mass_source: str = ""
    no_mass: str = ""
    """Why no mass source applies (shown instead of the generic "give --density ..." when set)."""


KEPT = "mass kept from file"
"""The mass source of a link whose tensor is recomputed around the file's own mass (its density unchanged)."""


def parse_masses(values: list[str] | None) -> dict[str, float]:
    """``LINK=KG`` pairs; malformed ones, and masses below :data:`SMALLEST_MASS`, raise UserError."""
    masses: dict[str, float] = {}
    for value in values or []:
        name, sep, kg = value.partition("=")
        try:
            mass = float(kg)
        except ValueError:
            mass = float("nan")
        if not sep or not name or not (math.isfinite(mass) and mass > 0):
            raise UserError(f"--mass {value!r}: expected LINK=KG with a positive mass, e.g. --mass link_4=0.35")
        if mass < SMALLEST_MASS:
            raise UserError(f"--mass {value!r}: must be a mass of at least {SMALLEST_MASS:g} kg")
        masses[name] = mass
    return masses


def _select(model, options: InertiaOptions) -> tuple[dict[str, str], list[LeftAlone]]:
    """``({link: why it is recomputed}, [flagged links left alone])``."""
    for name in [*(options.link_names or []), *options.masses]:
        if model.link(name) is None:
            raise UserError(f"{model.path}: no link named {name!r}")
    if options.all_links:
        return {link.name: "--all" for link in model.links}, []
    if options.link_names:
        return {name: "--links" for name in options.link_names}, []
    selected: dict[str, str] = {}
    left_alone: list[LeftAlone] = []
    for name, reason in links_needing_inertia(model).items():
        # One reason per link, from the first rule that flags it; I007 runs last, so a link whose
        # reason is I007 has nothing invalid (an invalid one would have been reported first).
        code = reason.split(" ", 1)[0]
        if code in IMPLAUSIBLE_CODES and not options.include_implausible and name not in options.masses:
            link = model.link(name)
            left_alone.append(LeftAlone(name, _element(link), link.line, code, reason))
        else:
            selected[name] = reason
    return selected, left_alone


def _left_alone_note(left_alone: list[LeftAlone]) -> str:
    names = listed(item.link for item in left_alone)
    codes = ", ".join(sorted({item.code for item in left_alone}))
    return (f"left {len(left_alone)} link(s) with valid but implausible inertia alone ({codes}): {names}; "
            f"add {INCLUDE_IMPLAUSIBLE} to recompute them")


def plan_inertia(model, document: Document, options: InertiaOptions) -> FixPlan:
    from ar3cli.fix import geometry_mass as inertia
    from ar3cli.maths import mass_properties as mp

    plan = FixPlan()
    cache: dict = {}
    rescaled, implausible = (set(), []) if options.all_links or options.link_names else \
        _rescale_units(model, document, plan, options)
    selected, left_alone = _select(model, options)
    selected = {name: reason for name, reason in selected.items() if name not in rescaled}
    left_alone = [item for item in left_alone if item.link not in rescaled]
    if left_alone:
        plan.notes.append(_left_alone_note(left_alone))
        plan.data["left_alone"] = [asdict(item) for item in left_alone]
    targets: list[_Target] = []
    for name, reason in selected.items():
        link = model.link(name)
        target = _Target(link, reason)
        if not link.has_geometry:
            if inertia.is_frame_link(model, link) and name not in options.masses:
                _write_frame_link(document, plan, link, reason)
            elif options.all_links and link.inertial is None:
                continue  # e.g. a geometry-less root: nothing to compute, nothing wrong
            else:
                plan.skipped.append(Skipped(_element(link), link.line,
                                            f"{reason}; no geometry to compute the inertia from"))
            continue
        try:
            target.geometry = inertia.geometry_mass(link, cache)
        except inertia.GeometryError as exc:
            plan.skipped.append(Skipped(_element(link), link.line, f"{reason}; {exc}"))
            continue
        targets.append(target)
    _assign_masses(model, targets, options, plan)
    for target in targets:
        if target.mass is None:
            plan.skipped.append(Skipped(_element(target.link), target.link.line, f"{target.reason}; " + (
                target.no_mass or f"no valid mass in the file: give --density, --mass {target.link.name}=KG "
                                  "or --total-mass")))
            continue
        props = mp.scaled_to_mass(target.geometry.props, target.mass)
        geometry_source = f"{target.geometry.role}: " + listed(target.geometry.sources, separator="; ")
        _write_inertial(document, plan, target.link, props, target.mass_source, geometry_source)
    new_mass = {target.link.name for target in targets if target.mass is not None and target.mass_source != KEPT}
    unexplained = [name for name in implausible if name not in new_mass]
    if unexplained:  # I013 names fix-inertia for grams only: say which densities it did not touch, and why
        plan.notes.append(f"left {len(unexplained)} link(s) whose density no material has alone (I013, not a mass in "
                          f"grams): {listed(unexplained)}; check their <mass> and collision sizes, or recompute "
                          "with --links NAME --density KG_PER_M3")
    plan.changes.sort(key=lambda change: change.line)
    plan.skipped.sort(key=lambda skipped: skipped.line)
    return plan


def _rescale_units(model, document: Document, plan: FixPlan, options: InertiaOptions) -> tuple[set[str], list[str]]:
    """Divide the mass and tensor of the links whose numbers the linter says are in another unit (a mass in
    grams, I013; a tensor in kg·mm² or g·mm², I007: :func:`~ar3cli.lint.rules.inertia.unit_mistakes`): the
    file's own values in kg and kg·m², the one right answer (centre of mass and axes kept). Links given a
    --mass, or whose findings an inline comment ignores, are left to the other paths. (The names done, the
    links whose I013 is not a mass in grams: fix-inertia says it leaves them, unless it recomputes them.)"""
    from ar3cli.lint.context import Context
    from ar3cli.lint.engine import suppressed_inline
    from ar3cli.lint.rules.inertia import unit_mistakes
    from ar3cli.lint.rules.plausibility import density_implausible

    context = Context(model)
    try:
        mistakes = unit_mistakes(context)
        implausible = [hit for hit in density_implausible.check(context)
                       if not suppressed_inline(hit.element, density_implausible.code)]
    finally:
        context.close()
    unexplained = [name for hit in implausible if (owner := _owning_link(hit.element)) is not None
                   and (name := owner.get("name", "")) not in mistakes]
    done: set[str] = set()
    for name, (mass_divisor, tensor_divisor, reason) in mistakes.items():
        link = model.link(name)
        inertial = link.inertial.element
        mass, tensor = inertial.find("mass"), inertial.find("inertia")
        if name in options.masses or any(suppressed_inline(element, code) for element, code in
                                         ((mass, "I013"), (tensor, "I007")) if element is not None):
            continue
        element = _element(link)
        if mass_divisor != 1.0:
            _set(document, plan, mass, "value", number(link.inertial.mass / mass_divisor), element, reason,
                 same=_same_numbers)
        if tensor_divisor != 1.0 and tensor is not None:
            old = {key: tensor.get(key) for key in TENSOR_KEYS}
            new = {key: number(value / tensor_divisor) for key, value in zip(TENSOR_KEYS, link.inertial.tensor)}
            span = document.span(tensor)
            for key, value in new.items():
                if not _same_numbers(old[key], value):
                    document.set_attribute(span, key, value)
            plan.changes.append(Change(element, tensor.sourceline or link.line, "inertia", _tensor_text(old),
                                       _tensor_text(new), reason))
        done.add(name)
    return done, unexplained


def _valid_file_mass(link) -> float | None:
    mass = link.inertial.mass if link.inertial is not None else None
    return mass if mass is not None and math.isfinite(mass) and mass > 0 else None


def _assign_masses(model, targets: list[_Target], options: InertiaOptions, plan: FixPlan) -> None:
    pending: list[_Target] = []
    for target in targets:
        name = target.link.name
        file_mass = _valid_file_mass(target.link)
        if name in options.masses:
            target.mass, target.mass_source = options.masses[name], f"--mass {name}={number(options.masses[name])}"
        elif file_mass is not None:
            target.mass, target.mass_source = file_mass, KEPT
        elif options.density is not None:
            target.mass = options.density * target.geometry.volume
            target.mass_source = (f"density {number(options.density)} kg/m3 x volume "
                                  f"{target.geometry.volume:.4g} m3")
        else:
            pending.append(target)
    if options.total_mass is not None and pending:
        _spread_total_mass(model, targets, pending, options.total_mass, plan)


def _spread_total_mass(model, targets: list[_Target], pending: list[_Target], total: float, plan: FixPlan) -> None:
    """Give the ``pending`` links with collision geometry what ``total`` leaves after the known
    masses, by volume; the visual-only ones get nothing and are named, with why."""
    physical = [t for t in pending if t.geometry.role == "collision"]
    markers = [t for t in pending if t.geometry.role != "collision"]
    for target in markers:
        target.no_mass = (f"visual geometry only (no <collision>): a marker or decoration, not a physical part, so "
                          f"it gets no share of --total-mass; give --mass {target.link.name}=KG (or --density) if "
                          "it weighs something")
    left_out = (f"; left out (visual geometry only, no <collision>): {listed(t.link.name for t in markers)}"
                if markers else "")
    if not physical:
        plan.notes.append(f"--total-mass: no link without a mass has collision geometry, nothing to spread "
                          f"{number(total)} kg onto{left_out}")
        return
    target_names = {t.link.name for t in targets}
    known = sum(t.mass for t in targets if t.mass is not None)
    known += sum(_valid_file_mass(link) or 0.0 for link in model.links if link.name not in target_names)
    remainder = total - known
    if not remainder > 0:
        raise UserError(f"--total-mass {number(total)} kg: the other links already weigh {known:.4g} kg, nothing "
                        f"is left for {listed(sorted(t.link.name for t in physical))}")
    volume = sum(t.geometry.volume for t in physical)
    shares = []
    for target in physical:
        share = target.geometry.volume / volume
        target.mass = remainder * share
        target.mass_source = (f"--total-mass {number(total)} kg: {remainder:.4g} kg left after the "
                              f"known masses, spread by collision volume ({share:.1%})")
        shares.append(f"{target.link.name} {share:.1%}")
    unselected = [link.name for link in model.links
                  if link.collisions and link.name not in target_names and _valid_file_mass(link) is None]
    if unselected:
        left_out += (f"; not selected, and weighing nothing in the file: {listed(unselected)} (name them with "
                     "--links, or use --all, to give them a share)")
    plan.notes.append(f"--total-mass: {known:.4g} kg in links with known masses, {remainder:.4g} kg spread by "
                      f"collision volume over {len(physical)} link(s): {listed(shares)}{left_out}")


def _element(link) -> str:
    return f"link {link.name} <inertial>"


def _write_frame_link(document: Document, plan: FixPlan, link, reason: str) -> None:
    import numpy as np

    from ar3cli.fix import geometry_mass as inertia
    from ar3cli.maths import mass_properties as mp

    props = mp.MassProperties(inertia.FRAME_LINK_MASS, np.zeros(3), np.eye(3) * inertia.FRAME_LINK_INERTIA)
    source = "frame link (no geometry, fixed joint): tiny inertial, see docs/commands/fix-inertia.md"
    _write_inertial(document, plan, link, props, source, source)


def _write_inertial(document: Document, plan: FixPlan, link, props: mp.MassProperties,
                    mass_source: str, geometry_source: str) -> None:
    """Queue the edits that make ``link``'s ``<inertial>`` say ``props`` (only fields that differ)."""
    xyz = " ".join(number(v) for v in _clean(props.com, absolute=1e-12))
    tensor = _clean(props.inertia, relative=1e-10)
    values = dict(zip(TENSOR_KEYS, (tensor[0, 0], tensor[0, 1], tensor[0, 2], tensor[1, 1], tensor[1, 2],
                                    tensor[2, 2])))
    new_tensor = {k: number(v) for k, v in values.items()}
    element = _element(link)
    if link.inertial is None:
        q = document.quote.decode()
        lines = ["<inertial>",
                 f"  <origin xyz={q}{xyz}{q} rpy={q}0 0 0{q}/>",
                 f"  <mass value={q}{number(props.mass)}{q}/>",
                 "  <inertia " + " ".join(f"{k}={q}{v}{q}" for k, v in new_tensor.items()) + "/>",
                 "</inertial>"]
        document.insert_child(document.span(link.element), lines)
        plan.changes.append(Change(element, link.line, "origin xyz", None, xyz, geometry_source))
        plan.changes.append(Change(element, link.line, "mass", None, number(props.mass), mass_source))
        plan.changes.append(Change(element, link.line, "inertia", None, _tensor_text(new_tensor), geometry_source))
        return
    inertial_element = link.inertial.element
    inertial_span = document.span(inertial_element)
    line = inertial_element.sourceline or link.line
    origin = inertial_element.find("origin")
    if origin is None:
        if not _same_numbers("0 0 0", xyz):  # an absent <origin> already says 0 0 0
            q = document.quote.decode()
            first = document.span(inertial_element).children
            document.insert_child(inertial_span, [f"<origin xyz={q}{xyz}{q} rpy={q}0 0 0{q}/>"],
                                  before=first[0] if first else None)
            plan.changes.append(Change(element, line, "origin xyz", None, xyz, geometry_source))
    else:
        _set(document, plan, origin, "xyz", xyz, element, geometry_source, same=_same_numbers)
        if origin.get("quat_xyzw") is None or origin.get("rpy") is not None:
            _set(document, plan, origin, "rpy", "0 0 0", element, "tensor written in the link frame",
                 same=_same_numbers, default="0 0 0")
        if origin.get("quat_xyzw") is not None:  # URDF 1.1's orientation: the identity in its own form
            _set(document, plan, origin, "quat_xyzw", "0 0 0 1", element, "tensor written in the link frame",
                 same=_same_numbers)
    mass = inertial_element.find("mass")
    if mass is None:
        document.insert_child(inertial_span, [f"<mass {document.format_attr('value', number(props.mass)).decode()}/>"])
        plan.changes.append(Change(element, line, "mass", None, number(props.mass), mass_source))
    else:
        _set(document, plan, mass, "value", number(props.mass), element, mass_source, same=_same_numbers)
    tensor_element = inertial_element.find("inertia")
    if tensor_element is None:
        document.insert_child(inertial_span, ["<inertia " + " ".join(
            document.format_attr(k, v).decode() for k, v in new_tensor.items()) + "/>"])
        plan.changes.append(Change(element, line, "inertia", None, _tensor_text(new_tensor), geometry_source))
        return
    old = {k: tensor_element.get(k) for k in TENSOR_KEYS}
    if all(_same_numbers(old[k], v) for k, v in new_tensor.items()):
        return
    span = document.span(tensor_element)
    for key, value in new_tensor.items():
        if not _same_numbers(old[key], value):
            document.set_attribute(span, key, value)
    plan.changes.append(Change(element, tensor_element.sourceline or line, "inertia",
                               _tensor_text(old), _tensor_text(new_tensor), geometry_source))


def _set(document: Document, plan: FixPlan, element, attribute: str, value: str, name: str, source: str,
         same, default: str | None = None) -> None:
    old = element.get(attribute)
    if same(old if old is not None else default, value):
        return
    document.set_attribute(document.span(element), attribute, value)
    label = f"{element.tag} {attribute}" if element.tag != "mass" else "mass"
    plan.changes.append(Change(name, element.sourceline or 0, label, old, value, source))


def _same_numbers(old: str | None, new: str) -> bool:
    """A computed number equals the file's to 1e-9 (relative) or 1e-15 (absolute, for zeros)."""
    return same_numbers(old, new, rel_tol=1e-9, abs_tol=1e-15)


def _clean(values: np.ndarray, relative: float = 0.0, absolute: float = 0.0) -> np.ndarray:
    """Zero out rounding noise: entries below ``absolute`` or ``relative`` x the largest entry
    (rotating a diagonal tensor by rpy angles leaves ~1e-17 off-diagonal residue)."""
    import numpy as np

    array = np.array(values, dtype=float)
    scale = float(np.max(np.abs(array))) if array.size else 0.0
    array[np.abs(array) < max(absolute, relative * scale)] = 0.0
    return array


def _tensor_text(values: dict[str, str | None]) -> str:
    return " ".join(f"{k}={values.get(k)}" for k in TENSOR_KEYS)


def links_needing_inertia(model: Model) -> dict[str, str]:
    """``{link name: "CODE name: message"}`` for every link the lint inertia rules that fix-inertia
    fixes (``FIXED_BY_FIX_INERTIA`` of lint/rules/inertia.py: I001-I009) flag.

    The linter is the one definition of "bad inertia": fix-inertia fixes exactly what it reports,
    so a fixed link lints clean. Inline ``<!-- ar3cli: ignore[CODE] -->`` suppressions are honoured.
    """
    from ar3cli.lint.context import Context
    from ar3cli.lint.engine import suppressed_inline
    from ar3cli.lint.rules.inertia import FIXED_BY_FIX_INERTIA

    context = Context(model)
    found: dict[str, str] = {}
    try:
        for rule in FIXED_BY_FIX_INERTIA:
            for hit in rule.check(context):
                element = _owning_link(hit.element)
                if element is None or suppressed_inline(hit.element, rule.code):
                    continue
                found.setdefault(element.get("name", ""), f"{rule.code} {rule.name}: {hit.message}")
    finally:
        context.close()
    return {link.name: found[link.name] for link in model.links if link.name in found}


def _owning_link(element):
    """The ``<link>`` element a hit's element belongs to (itself, or an ancestor)."""
    while element is not None and element.tag != "link":
        element = element.getparent()
    return element


FIXER = Fixer[InertiaOptions]("fix-inertia", plan_inertia, options=InertiaOptions, help="""\
Recompute mass, centre of mass and inertia tensor of links from their geometry.

By default it fixes only links whose inertia is invalid (missing, mass <= 0, not positive
definite, A + B < C, all zero), rescales a mass in grams or a tensor in kg*mm^2 / g*mm^2 where the
linter shows the unit (I013, I007), and lists the valid but implausible ones (I007) it left alone;
--include-implausible recomputes those too.
Edits only the fixed `<inertial>` elements, byte for byte, and writes atomically. A link
without a valid mass needs --density, --mass or --total-mass: there is no default density.
""")
"""``ar3cli fix-inertia``: :func:`plan_inertia` (nothing to verify in PyBullet: the lint of the result
is the check)."""
