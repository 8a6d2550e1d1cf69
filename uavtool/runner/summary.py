"""Human-readable progress lines and the end-of-flight summary (no printing here)."""

from __future__ import annotations

import json
import math
from typing import TYPE_CHECKING

from uavtool.mission import Status, Telemetry
from uavtool.terminal import counted, safe_text

if TYPE_CHECKING:
    from uavtool.runner.fleet import FleetSummary
    from uavtool.runner.fly import FlightSummary


def format_progress(text: str, t: Telemetry | None) -> str:
    if t is None:
        return f"[{'':>7s}] {text}"
    x, y, z = t.pos_enu_m
    return f"[{t.time_boot_ms / 1000:6.1f}s] {t.mode:<7s} E{x:6.1f} N{y:6.1f} U{z:5.1f}  {text}"


def format_summary(s: FlightSummary) -> str:
    o, e = s.outcome, s.evaluation
    lines = [
        "",
        f"outcome        {o.status.value}: {o.reason}",
        f"flight         {s.flight_time_s:.1f} s sim, route {s.route_length_m:.1f} m, "
        f"{counted(s.frames, 'photo')}, {s.wall_time_s:.1f} s wall",
    ]
    if s.searched:
        lines += _search_lines(s)
    else:
        lines.append(f"mission        {safe_text(s.mission)}")
        for result in s.results:
            values = safe_text(json.dumps(result.values))
            if len(values) > 200:
                values = values[:199] + "…"
            lines.append(f"result         {safe_text(result.tag)}: {values}")
    if s.clearance_m is not None:
        lines.append(
            f"clearance      {s.clearance_m:.2f} m from building {s.clearance_building!r} "
            "at the closest (the vehicle's body to any wall or roof)"
        )
    if e.tunnel_kept is not None:
        lines.append(f"tunnel         {'kept' if e.tunnel_kept else 'LOST'} in the model")
    if s.stale_dropped:
        kinds = ", ".join(f"{n} {name}" for name, n in s.stale_dropped)
        lines.append(
            f"link           {sum(n for _, n in s.stale_dropped)} stale messages dropped "
            f"(older than one already received: {kinds})"
        )
    if s.last_refusal:
        # A refusal the mission got past (a retried arming) is a remark; one it did not is
        # likely why it stopped.
        done = o.status in (Status.COMPLETED, Status.PARTIAL, Status.NO_MATCH)
        if done:
            lines.append(f"refused        {s.last_refusal} (the mission retried and went on)")
        else:
            lines.append(f"last refusal   {s.last_refusal}")
    lines.append(f"recording      {s.recording if s.recording else '(not recorded)'}")
    return "\n".join(lines)


def _search_lines(s: FlightSummary) -> list[str]:
    """What the built-in search found: the points of interest visited, the match, the model."""
    o, e = s.outcome, s.evaluation
    lines = []
    visited = [
        f"poi {k}" + (f" ({e.visited[i]})" if i < len(e.visited) else "")
        for i, k in enumerate(o.visited)
    ]
    lines.append(f"visited        {', '.join(visited) if visited else 'none'}")
    if o.matched_poi >= 0:
        name = f" = building {e.matched_building!r}" if e.matched_building else ""
        truth = ""
        if e.target_building:
            ok = "correct" if e.matched_building == e.target_building else "WRONG"
            truth = f" ({ok}: the target is {e.target_building!r})"
        lines.append(f"matched        poi {o.matched_poi}{name}, score {o.match_score:.3f}{truth}")
    else:
        lines.append("matched        nothing")
    if o.model_built:
        iou = f", IoU vs ground truth {e.model_iou:.3f}" if e.model_iou is not None else ""
        lines.append(f"model          built{iou}")
    else:
        lines.append("model          not built")
    return lines


def format_fleet_summary(s: FleetSummary) -> str:
    breach = s.closest_approach_m < s.separation_m
    lines = [
        "",
        f"outcome        {s.status.value}: {s.reason}",
        f"fleet          {counted(len(s.vehicles), 'vehicle')}, mission {safe_text(s.mission)}, "
        f"{s.vehicle_time_s:.1f} s {'sim' if s.lockstep else 'on the wall clock'}, "
        f"{s.wall_time_s:.1f} s wall",
    ]
    e = s.evaluation
    if e is not None and e.matched_building:
        right = "right" if e.matched_building == e.target_building else "WRONG"
        iou = f", model IoU {e.model_iou:.3f}" if e.model_iou is not None else ""
        lines.append(
            f"match          building {e.matched_building!r} ({right}: the target is "
            f"{e.target_building!r}){iou}"
        )
    if math.isfinite(s.closest_approach_m):
        a, b = s.closest_pair
        lines.append(
            f"separation     {s.closest_approach_m:.2f} m between vehicles {a} and {b} at the "
            f"closest ({'BREACHED: less than' if breach else 'kept:'} {s.separation_m:g} m)"
        )
    for v in s.vehicles:
        o = v.outcome
        lines.append(
            f"vehicle {v.sysid:<6d} {o.status.value}: {safe_text(o.reason)}; "
            f"{v.flight_time_s:.1f} s, route {v.route_length_m:.1f} m, {counted(v.frames, 'photo')}"
        )
        for result in v.results:
            values = safe_text(json.dumps(result.values))
            lines.append(f"  result       {safe_text(result.tag)}: {values[:200]}")
        if v.clearance_m is not None:
            lines.append(f"  clearance    {v.clearance_m:.2f} m from the nearest building")
    lines.append(f"recording      {s.recording if s.recording else '(not recorded)'}")
    return "\n".join(lines)
