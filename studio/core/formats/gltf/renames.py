"""Shape keys renamed in another tool between the studio's export and a re-export.

The studio's set-up (carried in the extras, or in the neutral normal map after a re-export that
drops extras) names key poses: links, curves, technique-2 areas and timeline tracks. A person
who renames a shape key in Blender (browInnerUp_L → browRaise) keeps the key, under a name the
set-up no longer finds. As Blender matches a re-imported shape key to an action's channel by
name, we match by name first; the set-up's names left unmatched are then paired with the file's
unmatched keys by their place among the keys (the export writes ``poses``, its keys in order,
for this). The file's name wins, one report line per rename. A set-up name with no key left to
pair with (the key deleted) takes its links, areas and track with it, in one line each.
"""

from __future__ import annotations

from typing import Any


def pose_renames(saved: list[str] | None, found: list[str], used: set[str]
                 ) -> dict[str, str | None]:
    """{set-up name: file name, or None for a key that is gone} for every name the set-up
    uses (``used``) or listed (``saved``: the export's keys in order, None in files written
    before it was) that the file's keys (``found``) lack."""
    present = set(found)
    order = [n for n in (saved or []) if isinstance(n, str)]
    missing = [n for n in dict.fromkeys([*order, *sorted(used)]) if n not in present]
    if not missing:
        return {}
    out: dict[str, str | None] = dict.fromkeys(missing)
    if len(order) == len(found):  # the same keys, some renamed: pair them by place
        for old, new in zip(order, found, strict=True):
            if old in out and new not in order:
                out[old] = new
    else:  # keys added or deleted too: pair the unmatched in order
        spare = [n for n in found if n not in order and n not in used]
        for old, new in zip([n for n in missing if n in order], spare, strict=False):
            out[old] = new
    return out


def used_poses(extras: dict[str, Any]) -> set[str]:
    """The key poses the set-up in ``extras`` refers to."""
    influence = extras.get("influence", {})
    names = set(influence.get("links", {})) | set(influence.get("curves", {}))
    names |= {a["pose"] for a in extras.get("wdv", {}).get("areas", [])}
    names |= {t["pose"] for t in extras.get("timeline", {}).get("tracks", [])}
    return {str(n) for n in names}


def renamed_extras(extras: dict[str, Any], renames: dict[str, str | None]
                   ) -> tuple[dict[str, Any], list[str]]:
    """``extras`` with every pose name in ``renames`` replaced (or its uses left out, for None),
    and one report line per name."""
    if not renames:
        return extras, []

    def keyed(table: dict) -> dict:
        return {renames.get(k, k): v for k, v in table.items() if renames.get(k, k) is not None}

    out = dict(extras)
    influence = dict(extras.get("influence", {}))
    for part in ("links", "curves"):
        if part in influence:
            influence[part] = keyed(influence[part])
    out["influence"] = influence
    if "wdv" in extras:  # an area with no pose left stays in its place (None): the carried
        # per-vertex data is numbered by place
        out["wdv"] = {**extras["wdv"], "areas": [{**a, "pose": renames.get(a["pose"], a["pose"])}
                                                 for a in extras["wdv"].get("areas", [])]}
    if "timeline" in extras:
        out["timeline"] = {**extras["timeline"], "tracks": [
            {**t, "pose": renames.get(t["pose"], t["pose"])}
            for t in extras["timeline"].get("tracks", []) if renames.get(t["pose"], t["pose"])]}
    lines = [f"shape key '{new}' is the set-up's '{old}' (renamed since the export; matched "
             "by its place among the shape keys)" if new is not None else
             f"the set-up's key pose '{old}' is not among the file's shape keys: its links, "
             "technique-2 areas and timeline track are left out"
             for old, new in renames.items()]
    return out, lines
