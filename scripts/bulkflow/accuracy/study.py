"""Run a family, measure each member, and write out/accuracy/<kind>/<kind>.{csv,png,json}.

A kind is a dict (see wave_bar.KIND): its members (each with the size `h` and a label), a scene
writer, a measure (the member's `value` and, for an exact reference, its relative `error`), and
whether the reference is exact or Richardson-extrapolated from the three finest members.

A measure may return `value` None: the member ran but its quantity does not exist (bin-tss: the
run ended before the end of steady discharge). Such a member keeps its row (cost, and why, in
the kind's own columns) with no error; it is never replaced by a number, and a Richardson
reference is only formed when the three finest members all have a value.
"""
from __future__ import annotations

import csv
import json
import math
import os
import time
from pathlib import Path

from .convergence import order_from_errors, order_from_values, recommend, richardson
from .runs import reuse_name, run_deck, run_deck_reusing

TARGETS = (0.01, 0.02, 0.05)


def run_family(kind: dict, quick: bool, out: Path, ranks: int = 1, solver: str | None = None, log=print,
               reuse: bool = False) -> dict:
    """reuse: a member whose deck, rank count and solver binary ran to the end in OUT/runs before
    is not run again; its row keeps the wall and CPU times measured then (runs.run_deck_reusing).
    Not for kinds whose member is a search (arching-cow)."""
    out = Path(out)
    runs = out / "runs"
    rows = []
    t_start = time.perf_counter()
    if reuse and "run" in kind:
        raise ValueError(f"{kind['name']}: a member is a search of several runs; reuse is not supported")
    members = kind["members"](quick)
    for member in members:
        name = f"{kind['name'].replace('-', '_')}_{len(rows)}"
        reused = False
        if "run" in kind:                  # a member that is more than one solver run (a search)
            timing, res = kind["run"](member, runs, ranks, solver)
        else:
            text = kind["scene"](member)
            if reuse:
                # named by the deck's key and not the member's place: a family extended by a finer
                # member or started with another list finds its members wherever they were
                name = reuse_name(kind["name"].replace("-", "_"), text, ranks, solver)
            log(f"  ... {member['label']} (member {len(rows) + 1} of {len(members)}; "
                f"solver progress: {runs / name}.log)")
            if reuse:
                timing, reused = run_deck_reusing(text, runs, kind["name"].replace("-", "_"), ranks=ranks,
                                                  solver=solver)
            else:
                timing = run_deck(text, runs, name, ranks=ranks, solver=solver)
            res = kind["measure"](timing.base, member)
        work = res.pop("work_override", None)
        row = {"label": member["label"], "h": member["h"], **{k: v for k, v in member.items()
                                                              if k not in ("label", "h")},
               "wall": timing.wall, "cpu": timing.cpu, "increments": timing.increments, "ranks": ranks,
               **res}
        if reuse:
            row["reused"] = reused
        # the work (element- or particle-steps) orders the members by cost independently of the
        # machine's load; the wall and CPU times are what was measured
        row["work"] = work if work is not None else timing.increments * (res.get("particles") or member["elements"])
        rows.append(row)
        log(f"  {member['label']:<40s} value {_show_value(res['value'])}"
            + (f"  error {100 * res['error']:.3g} %" if res.get("error") is not None else "")
            + f"  [{timing.wall:.2f} s wall, {timing.cpu:.2f} s cpu, {timing.increments} inc"
            + ("; reused: measured by an earlier run" if reused else "") + "]")
    summary = summarise(kind, rows)
    summary["total_wall"] = time.perf_counter() - t_start
    summary["quick"] = quick
    write_outputs(kind, rows, summary, out)
    return summary


def _show_value(v) -> str:
    return "none (not measured)" if v is None else f"{v:.6g}"


def missing_values(rows: list[dict], key: str = "value") -> list[str]:
    """Labels of the members without a value for `key` (None or not a number), coarse to fine."""
    return [r["label"] for r in sorted(rows, key=lambda r: -r["h"])
            if r.get(key) is None or not math.isfinite(r[key])]


def resummarise(kind: dict, out: Path) -> dict:
    """Summary and outputs again from the measured rows of an earlier run's <kind>.json (no solver
    run): for a changed summary rule without repeating a long family."""
    stem = Path(out) / kind["name"]
    old = json.loads(Path(f"{stem}.json").read_text())
    keep = ("label", "h", "wall", "cpu", "increments", "ranks", "work", "value", "particles", "elements",
            "n", "cell", "n_arc", "tol", "no_flow", "flow", "runs", "quick_case", "sv_l2", "sv_centroid",
            "k0", "settlement", "wall_force", "edge_cells", "tss_status", "tss_rule", "steady_windows",
            "mdr", "discharged", "reused")
    rows = [{k: m[k] for k in keep if k in m} for m in old["members"]]
    if kind["reference"] == "exact":
        for r, m in zip(rows, old["members"]):
            r["error"] = m["error"]
    summary = summarise(kind, rows)
    summary["total_wall"] = old["total_wall"]
    summary["quick"] = old.get("quick")
    write_outputs(kind, rows, summary, Path(out))
    return summary


def also_summary(kind: dict, rows: list[dict]) -> dict:
    """Observed order and Richardson reference of the kind's secondary quantities (`also`)."""
    out = {}
    for key, what in kind.get("also", {}).items():
        missing = missing_values(rows, key)
        if len(missing) == len(rows):
            continue
        if missing_values(sorted(rows, key=lambda r: r["h"])[:3], key):
            out[key] = {"what": what, "observed_order": math.nan, "reference": None,
                        "note": "not measured at " + ", ".join(missing) + " (the three finest members need it)"}
            continue
        measured = [r for r in rows if r["label"] not in missing]     # coarser members may lack it
        h, values = [r["h"] for r in measured], [r[key] for r in measured]
        entry = {"what": what, "observed_order": order_from_values(h, values)}
        try:
            rich = richardson(h, values)
            entry.update(reference=rich.value, uncertainty=rich.uncertainty, gci=rich.gci)
            finest = min(measured, key=lambda r: r["h"])
            entry["finest_error"] = abs(finest[key] / rich.value - 1)
        except ValueError as exc:
            entry.update(reference=None, note=str(exc))
        out[key] = entry
    return out


def summarise(kind: dict, rows: list[dict]) -> dict:
    """Reference, observed order and the recommendations of a measured family (rows get `error`
    filled in when the reference is extrapolated). The cheapest member is the one of least work
    (increments × elements or particles): in one family the solver's time is proportional to it,
    while the measured wall time of a short run is mostly start-up and the machine's load."""
    h = [r["h"] for r in rows]
    summary = {"also": also_summary(kind, rows),
               "kind": kind["name"], "title": kind["title"], "quantity": kind["quantity"],
               "error_measure": kind["error_measure"], "expected_order": kind["expected_order"],
               "reference_kind": kind["reference"]}
    if kind["reference"] == "exact":
        summary["observed_order"] = order_from_errors(h, [r["error"] for r in rows])
        fine = sorted(rows, key=lambda r: r["h"])[:3]
        summary["monotone"] = bool(fine[0]["error"] < fine[1]["error"] < fine[2]["error"])
        summary["reference"] = kind.get("exact_value")
    elif missing_values(sorted(rows, key=lambda r: r["h"])[:3]):
        return _summary_with_missing(kind, rows, summary)
    else:
        # coarser members without a value (the three finest have one) keep no error
        missing = missing_values(rows)
        measured = [r for r in rows if r["label"] not in missing]
        for r in rows:
            if r["label"] in missing:
                r["error"] = None
        h, values = [r["h"] for r in measured], [r["value"] for r in measured]
        try:
            rich = richardson(h, values)
        except ValueError as exc:
            # no observed order: report against the finest member, say so, recommend nothing
            summary.update(observed_order=order_from_values(h, values), reference=None, reference_uncertainty=None,
                           gci_finest=None, reference_note=str(exc))
            finest, second = sorted(measured, key=lambda r: r["h"])[:2]
            spread = abs(second["value"] / finest["value"] - 1)
            for r in measured:
                r["error"] = abs(r["value"] / finest["value"] - 1)
            summary.update(finest_error=None, finest_label=finest["label"], members=rows,
                           recommendations=[{"target": t, "label": None, "h": None, "wall": None,
                                             "line": f"for ±{100 * t:g} % {kind['quantity']}: no reference "
                                                     f"(no usable observed order), no recommendation; the two finest "
                                                     f"differ by {100 * spread:.2g} %"}
                                            for t in TARGETS])
            return summary
        summary["observed_order"] = rich.order
        summary["reference"] = rich.value
        summary["reference_uncertainty"] = rich.uncertainty
        summary["gci_finest"] = rich.gci
        for r in measured:
            r["error"] = abs(r["value"] - rich.value) / abs(rich.value)
    finest = min(rows, key=lambda r: r["h"])
    summary["finest_error"] = finest["error"]
    summary["finest_label"] = finest["label"]
    summary["recommendations"] = []
    for target in TARGETS:
        pick = recommend(rows, target, key_cost="work")
        if pick is None:
            line = f"for ±{100 * target:g} % {kind['quantity']}: no member of this family reaches it"
        else:
            line = (f"for ±{100 * target:g} % {kind['quantity']}: {pick['label']}, "
                    f"{pick['wall']:.3g} s on {pick['ranks']} rank(s) ({pick['cpu']:.3g} s CPU; "
                    f"error {100 * pick['error']:.2g} %)")
        summary["recommendations"].append({"target": target, "label": pick and pick["label"],
                                           "h": pick and pick["h"], "wall": pick and pick["wall"],
                                           "line": line})
    summary["members"] = rows
    return summary


def _summary_with_missing(kind: dict, rows: list[dict], summary: dict) -> dict:
    """Summary of a Richardson family one of whose three finest members has no value: no order, no
    reference, no recommendation; the members with a value are compared with the finest of them."""
    missing = missing_values(rows)
    note = (f"{kind['quantity']} not measured at {', '.join(missing)}: no extrapolation "
            "(it needs a value at each of the three finest members)")
    measured = sorted((r for r in rows if r["label"] not in missing), key=lambda r: r["h"])
    for r in rows:
        r["error"] = None
    if measured and measured[0]["value"] != 0:
        for r in measured:
            r["error"] = abs(r["value"] / measured[0]["value"] - 1)
    summary.update(observed_order=math.nan, reference=None, reference_uncertainty=None, gci_finest=None,
                   reference_note=note, finest_error=None,
                   finest_label=measured[0]["label"] if measured else None, members=rows,
                   recommendations=[{"target": t, "label": None, "h": None, "wall": None,
                                     "line": f"for ±{100 * t:g} % {kind['quantity']}: no reference "
                                             f"({kind['quantity']} not measured at every one of the three "
                                             "finest members), no recommendation"}
                                    for t in TARGETS])
    return summary


def write_outputs(kind: dict, rows: list[dict], summary: dict, out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    stem = out / kind["name"]
    keys = []
    for r in rows:
        keys += [k for k in r if k not in keys]
    with open(f"{stem}.csv", "w", newline="") as handle:
        w = csv.DictWriter(handle, fieldnames=keys)
        w.writeheader()
        for r in rows:
            w.writerow(r)
    Path(f"{stem}.json").write_text(json.dumps(summary, indent=2, default=_json_default) + "\n")
    Path(f"{stem}.md").write_text(markdown(kind, rows, summary))
    plot(kind, rows, summary, Path(f"{stem}.png"))


def markdown(kind: dict, rows: list[dict], summary: dict) -> str:
    """The family as the Markdown table docs/accuracy.md shows, with the summary lines."""
    also = [k for k in kind.get("also", {}) if all(k in r for r in rows)]
    lines = [f"| member | {kind['parameter']} ({kind['parameter_unit']}) | value | error | "
             + "".join(f"{k} | " for k in also) + "increments | work | wall (s) | CPU (s) |",
             "|---|---|---|---|" + "---|" * len(also) + "---|---|---|---|"]
    for r in sorted(rows, key=lambda r: -r["h"]):
        lines.append(f"| {r['label']} | {r['h']:.4g} | {_cell_value(r)} | {_cell_error(r.get('error'))} | "
                     + "".join(f"{_cell(r[k])} | " for k in also)
                     + f"{r['increments']} | {r['work']:.3g} | {r['wall']:.3g} | {r['cpu']:.3g} |")
    p = summary["observed_order"]
    ref = "exact" if summary["reference_kind"] == "exact" else (
        f"none — {summary['reference_note']}" if summary["reference"] is None else
        f"Richardson {summary['reference']:.6g} ± {summary['reference_uncertainty']:.2g} "
        f"(GCI {100 * summary['gci_finest']:.2g} %)")
    if summary["reference"] is None and summary["reference_kind"] != "exact":
        lines[0] = lines[0].replace("| error |", "| vs finest |")
    lines += ["", f"Reference: {ref}. Observed order (three finest): "
              + ("none" if p is None or p != p else f"{p:.2f}")
              + ("" if summary.get("monotone", True) else " (the error does not fall: no order)")
              + f". Total wall time {summary['total_wall']:.0f} s on {rows[0]['ranks']} rank(s).", ""]
    lines += [f"- {r['line']}" for r in summary["recommendations"]]
    for key, e in summary.get("also", {}).items():
        ref = (f"Richardson {e['reference']:.6g} ± {e['uncertainty']:.2g}, finest {100 * e['finest_error']:.2g} % "
               f"from it" if e["reference"] is not None else f"no reference — {e['note']}")
        lines.append(f"- also {e['what']} (CSV column `{key}`): {ref}")
    return "\n".join(lines) + "\n"


def _cell(v) -> str:
    return "–" if v is None or (isinstance(v, float) and not math.isfinite(v)) else f"{v:.5g}"


def _cell_value(r: dict) -> str:
    """A member's value (with a search's interval, no flow .. flow, when it has one), or why it has none
    (the kind's `tss_status`-like column, else 'none')."""
    if r["value"] is not None:
        if r.get("no_flow") is not None and r.get("flow") is not None:
            return f"{r['value']:.6g} ({r['no_flow']:.6g} .. {r['flow']:.6g})"
        return f"{r['value']:.6g}"
    return next((f"none ({r[k]})" for k in ("tss_status",) if r.get(k)), "none")


def _cell_error(e) -> str:
    return "–" if e is None else f"{100 * e:.3g} %"


def _json_default(x):
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return float(x)


def plot(kind: dict, rows: list[dict], summary: dict, path: Path) -> None:
    """Left: error against wall time (targets dashed); right: error against h with the observed
    order. Without a reference (no usable order) the values themselves are drawn instead."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    import matplotlib.pyplot as plt

    fig, (ax1, ax2) = plt.subplots(1, 2, figsize=(11, 4.2))
    no_ref = summary["reference_kind"] != "exact" and summary["reference"] is None
    # members without a value (or, with a reference, without an error) have no point to draw
    n_all = len(rows)
    rows = sorted((r for r in rows if r["value"] is not None and (no_ref or r.get("error") is not None)),
                  key=lambda r: -r["h"])
    not_drawn = f"; {n_all - len(rows)} member(s) without a value not drawn" if len(rows) < n_all else ""
    if not rows:
        fig.suptitle(f"{kind['name']}: no member has a value", fontsize=10)
        fig.savefig(path, dpi=110)
        plt.close(fig)
        return
    wall = [r["wall"] for r in rows]
    h = [r["h"] for r in rows]
    if no_ref:
        y = [r["value"] for r in rows]
        ax1.semilogx(wall, y, "o-")
        ax2.semilogx(h, y, "s-", label="measured")
        if all(r.get("no_flow") is not None and r.get("flow") is not None for r in rows):
            # a search's value is known only to its interval: draw it, so that a drift smaller than
            # the bisection's tolerance is not read as one
            ax2.errorbar(h, y, yerr=[[r["value"] - r["no_flow"] for r in rows], [r["flow"] - r["value"] for r in rows]],
                         fmt="none", ecolor="k", capsize=4, label="search interval (no flow .. flow)")
        for ax in (ax1, ax2):
            ax.set_ylabel(kind["quantity"])
        ax2.set_title(f"{kind['quantity']} against {kind['parameter']}: no usable observed order, "
                      f"no reference{not_drawn}", fontsize=9)
    else:
        y = [100 * max(r["error"], 1e-12) for r in rows]
        ax1.loglog(wall, y, "o-")
        for target in TARGETS:
            ax1.axhline(100 * target, color="grey", lw=0.6, ls="--")
        ax2.loglog(h, y, "s-", label="measured")
        p = summary["observed_order"]
        if p and math.isfinite(p):
            ax2.loglog(h, [y[-1] * (x / h[-1]) ** p for x in h], "k:", label=f"observed order {p:.2f}")
        for ax in (ax1, ax2):
            ax.set_ylabel("relative error, %")
        ref = "exact" if kind["reference"] == "exact" else "Richardson-extrapolated"
        ax2.set_title(f"{kind['quantity']}: error against {kind['parameter']} ({ref} reference){not_drawn}",
                      fontsize=9)
    for r, w, v in zip(rows, wall, y):
        ax1.annotate(f"{kind['parameter']} {r['h']:.3g}", (w, v), textcoords="offset points", xytext=(4, 4),
                     fontsize=8)
    ax1.set_xlabel(f"wall time per member, s ({rows[0]['ranks']} rank(s); shared machine)")
    ax1.set_title(f"{kind['name']}: against wall time", fontsize=10)
    ax2.set_xlabel(f"{kind['parameter']}, {kind['parameter_unit']}")
    ax2.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
