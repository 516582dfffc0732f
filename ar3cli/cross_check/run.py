"""cross-check's run and report: measure both engines, compare, explain the largest disagreements."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from ar3cli.output.report import Report, Table, log
from ar3cli.urdf.model import Model

COLUMNS = ["quantity", "where", "pybullet", "mujoco", "difference", "tolerance", "diagnosis"]


def cross_check(model: Model, path: Path, samples: int, seed: int, stability: bool = False, top: int = 10,
                announce: bool = True) -> Report:
    """Both engines at the home pose and ``samples`` configurations from ``seed``; the report (ok = agreement)."""
    from ar3cli.cross_check.compare import compare
    from ar3cli.cross_check.measure import measure_mujoco, plan_and_measure_pybullet

    if announce:
        log(f"cross-check: {path}: home + {samples} configurations (seed {seed}) in PyBullet and MuJoCo")
    plan, pb = plan_and_measure_pybullet(model, samples, seed)
    mj = measure_mujoco(model, plan)
    rows = compare(model, plan, pb, mj)
    bad = [row for row in rows if not row.agrees]
    diagnoses = list(dict.fromkeys(row.diagnosis for row in bad if row.diagnosis))
    notes = _notes(pb, mj)
    drops = _stability(model) if stability else []
    unstable = [drop for drop in drops if not drop["stable"]]
    data: dict[str, Any] = {
        "path": str(path), "samples": samples, "seed": seed, "agree": not bad and not unstable,
        "compared": len(rows), "disagreements": len(bad), "diagnoses": diagnoses, "notes": notes,
        "largest": [row.to_dict() for row in rows[:top]], "rows": [row.to_dict() for row in bad],
        "stability": drops,
    }
    table = Table(f"PyBullet vs MuJoCo: {path} (largest differences against their tolerances)", COLUMNS,
                  [[r.quantity, r.where, f"{r.pybullet:.6g}", f"{r.mujoco:.6g}", f"{r.difference:.3g}",
                    f"{r.tolerance:.3g}", r.diagnosis or ("" if r.agrees else "unknown")] for r in rows[:top]],
                  numeric_columns=("pybullet", "mujoco", "difference", "tolerance"))
    tables = [table]
    if drops:
        tables.append(Table("Passive drop (1 s, at rest under gravity)", ["engine", "timestep (s)", "energy growth (J)",
                                                                            "allowed (J)", "verdict"],
                            [[d["engine"], f"{d['timestep']:.4g}", "NaN" if d["energy_growth"] is None
                              else f"{d['energy_growth']:.3g}", f"{d['allowed_growth']:.3g}",
                              "stable" if d["stable"] else "UNSTABLE"] for d in drops], status_column="verdict"))
    lines = [f"note: {note}" for note in notes] + [f"diagnosis: {text}" for text in diagnoses]
    verdict = (f"agree: {len(rows)} values within tolerance" if not bad else
               f"DISAGREE: {len(bad)} of {len(rows)} values beyond tolerance")
    if unstable:
        verdict += "; unstable: " + ", ".join(f"{d['engine']} at {d['timestep']:.4g} s" for d in unstable)
    return Report(data, tables, [*lines, verdict], ok=not bad and not unstable)


def _notes(pb: Any, mj: Any) -> list[str]:
    notes = list(dict.fromkeys([*pb.notes, *mj.notes]))
    fused = mj.extra.get("fused", 0)
    if fused:
        notes.append(f"MuJoCo's default compile fuses {fused} link(s) joined by fixed joints into their parents "
                     "(fusestatic); compared unfused, so every link has a frame in both")
    if mj.extra.get("equalities"):
        notes.append(f"MuJoCo turns {mj.extra['equalities']} <mimic> element(s) into equality constraints; "
                     "PyBullet's loadURDF ignores <mimic>")
    notes += [f"MuJoCo cannot read a mesh: {text}" for text in mj.extra.get("substitutions", [])]
    return notes


def _stability(model: Model) -> list[dict[str, Any]]:
    from ar3cli.cross_check.stability import drop_mujoco, drop_pybullet

    return [*drop_pybullet(model), *drop_mujoco(model)]
