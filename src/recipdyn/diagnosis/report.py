"""The evaluation of a diagnoser as files: ``evaluation.json``, ``evaluation.md`` (tables)
and figures (confusion matrix, reliability diagram, recall against severity)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

__all__ = ["write_report", "markdown"]


def markdown(ev: dict[str, Any], classes: list[str]) -> str:
    f = ev["full"]
    co = ev["condition_only"]
    lines = [
        f"Held-out conditions {ev['test_conditions']}: {ev['n_test']} test records "
        f"({ev['n_train']} training).",
        "",
        "| features the record has | accuracy | moderate and severe | ECE |",
        "|---|---|---|---|",
    ]
    for k in ("full", "no_pressure", "vibration_only"):
        e = ev[k]
        lines.append(
            f"| {k} | {e['accuracy']:.3f} | {e['accuracy_moderate_severe']:.3f} | {e['ece']:.3f} |"
        )
    lines += ["", "| class | recall | detection limit (severity, value) |", "|---|---|---|"]
    for c in classes:
        d = f["detection"].get(c)
        lim = (
            "—"
            if d is None
            else (
                "not reached"
                if d["limit_severity"] is None
                else f"{d['limit_severity']:.2f} ({d['limit_value']:.3g} {d['unit']})"
            )
        )
        lines.append(f"| {c} | {f['recall'][c]:.2f} | {lim} |")
    lines += [
        "",
        "| fault | severity: median relative error | 90 % interval coverage | half-width |",
        "|---|---|---|---|",
    ]
    for c, s in ev["severity"].items():
        lines.append(
            f"| {c} | {s['median_relative_error']:.2f} | {s['coverage']:.2f} | "
            f"{s['half_width']:.2f} |"
        )
    lines += [
        "",
        f"Condition-only classifier: accuracy {co['accuracy']:.3f}, chance {co['chance']:.3f} "
        f"(bound {co['bound']:.3f}). Out-of-distribution false refusals on the held-out "
        f"conditions: {ev['ood_false_refusals']:.3f}.",
        "",
        "Permutation importance (accuracy drop): "
        + ", ".join(f"{n} {v:.3f}" for n, v in ev["importance"][:10]),
        "",
    ]
    return "\n".join(lines)


def write_report(ev: dict[str, Any], diag, folder: str | Path) -> list[Path]:
    """Write the evaluation's tables and figures into ``folder``; returns the paths."""
    from ..io import jsonable
    from ..mplstyle import _mpl

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    classes = diag.classes
    paths = [folder / "evaluation.json", folder / "evaluation.md"]
    paths[0].write_text(json.dumps(jsonable(ev), indent=1), encoding="utf-8")
    paths[1].write_text(markdown(ev, classes), encoding="utf-8")
    plt = _mpl()
    f = ev["full"]
    cm = np.asarray(f["confusion"], float)
    fig, ax = plt.subplots(figsize=(6.5, 5.5))
    norm = cm / np.maximum(cm.sum(axis=1, keepdims=True), 1)
    ax.imshow(norm, cmap="Blues", vmin=0, vmax=1)
    for i in range(cm.shape[0]):
        for j in range(cm.shape[1]):
            if cm[i, j]:
                ax.text(j, i, int(cm[i, j]), ha="center", va="center", fontsize=8)
    ax.set_xticks(range(len(classes)), classes, rotation=60, ha="right", fontsize=8)
    ax.set_yticks(range(len(classes)), classes, fontsize=8)
    ax.set_xlabel("predicted")
    ax.set_ylabel("true")
    ax.set_title(f"held-out conditions: accuracy {f['accuracy']:.2f}")
    paths.append(folder / "confusion.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(4.5, 4.5))
    rel = np.asarray(f["reliability"], float).reshape(-1, 3)
    ax.plot([0, 1], [0, 1], "k--", lw=0.8, label="calibrated")
    ax.plot(rel[:, 0], rel[:, 1], "o-", label=f"diagnoser (ECE {f['ece']:.3f})")
    ax.set_xlabel("top-class probability")
    ax.set_ylabel("fraction correct")
    ax.set_xlim(0, 1)
    ax.set_ylim(0, 1)
    ax.legend(loc="upper left", fontsize=8)
    paths.append(folder / "reliability.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(6, 4))
    for c, d in f["detection"].items():
        s = sorted(d["recall_by_severity"])
        ax.plot(s, [d["recall_by_severity"][v] for v in s], "o-", label=c)
    ax.axhline(0.9, color="k", lw=0.8, ls="--")
    ax.set_xlabel("severity (0 mildest, 1 most severe in the data set)")
    ax.set_ylabel("recall on held-out conditions")
    ax.set_ylim(-0.02, 1.02)
    ax.legend(fontsize=7, loc="lower right")
    paths.append(folder / "detection.png")
    fig.savefig(paths[-1], dpi=110, bbox_inches="tight")
    plt.close(fig)
    return paths
