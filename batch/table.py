#!/usr/bin/env python3
"""The batch's tables and plot (batch/Snakefile): from each recording's step status files and its
daylit outputs under OUT/REC/, writes

  OUT/results.csv  one row per recording: its status (ok, or failed with the step and daylit's
                   one-line error), frames, speed, and the lighting's figures (the 90% interval's
                   median half-widths; against ground truth, where the recording has it, the
                   worst burst's error, the 90th percentile, the bursts the interval held)
  OUT/bursts.csv   one row per burst of every recording: `recording`, then the columns of its
                   bursts.csv (daylit estimate)
  OUT/summary.png  per recording and burst, the worst channel's error against truth and the 90%
                   interval's half-width (E_sun, E_sky); recordings that failed are named

  table.py --out OUT --last STEP [--incomplete] REC...

--incomplete: some jobs did not finish (Snakemake's onerror); their recordings are listed as
failed with the step that did not finish.
"""
import argparse
import csv
import io
import json
import math
import os
import sys

sys.dont_write_bytecode = True  # no __pycache__ in the source tree
from files import write_atomically  # noqa: E402

STEPS = ["info", "bake", "estimate", "replay"]
COLUMNS = [
    "recording", "status", "failed_step", "reason", "frames", "bursts", "estimate_fps", "estimate_ms",
    "replay_fps", "sun_half_width", "sky_half_width", "worst_burst_error", "worst_burst",
    "p90_worst_channel_error", "interval_held_bursts", "interval_bursts", "frames_held",
]


def read_status(out, rec, step):
    try:
        with open(os.path.join(out, rec, step + ".status"), encoding="utf-8") as f:
            return f.readline().strip()
    except FileNotFoundError:
        return None


def read_json(path):
    try:
        with open(path, encoding="utf-8") as f:
            return json.load(f)
    except (FileNotFoundError, json.JSONDecodeError):
        return {}


def figure(figures, key):
    """A figure of daylit's figures.json (flat, "a/b/c" keys), else None."""
    value = figures.get(key)
    return value if isinstance(value, (int, float)) and not isinstance(value, bool) else None


def read_bursts(path):
    try:
        with open(path, newline="", encoding="utf-8") as f:
            return list(csv.DictReader(f))
    except FileNotFoundError:
        return []


def number(text):
    try:
        value = float(text)
    except (TypeError, ValueError):
        return None
    return value if math.isfinite(value) else None


def burst_errors(row, quantities=("sun", "sky")):
    """The burst's |median error| against truth in every channel of `quantities` (none without truth)."""
    errors = [number(row.get(f"{q}_error_{c}")) for q in quantities for c in "rgb"]
    return [abs(e) for e in errors if e is not None]


def burst_worst_error(row):
    errors = burst_errors(row)
    return max(errors) if errors else None


def burst_half_width(row, quantity):
    """The 90% interval's relative half-width, mean over channels, from its bounds in bursts.csv."""
    widths = []
    for c in "rgb":
        value, lo, hi = (number(row.get(f"{quantity}_{c}{s}")) for s in ("", "_lo", "_hi"))
        if value and lo is not None and hi is not None and value > 0:
            widths.append((hi - lo) / (2 * value))
    return sum(widths) / len(widths) if widths else None


def recording_row(out, rec, last, incomplete):
    row = {c: "" for c in COLUMNS}
    row["recording"] = rec
    steps = STEPS[: STEPS.index(last) + 1]
    for step in steps:
        status = read_status(out, rec, step)
        if status == "ok":
            continue
        row["status"] = "failed"
        row["failed_step"] = step
        if status is None:
            row["reason"] = (f"the {step} job did not finish (see {rec}/logs/{step}.log and the engine's log)"
                             if incomplete else f"no status for {step}")
        elif status.startswith("failed: "):
            row["reason"] = status[len("failed: "):]
        else:
            row["reason"] = status
        return row, []
    row["status"] = "ok"
    estimate = read_json(os.path.join(out, rec, "estimate", "figures.json"))
    replay = read_json(os.path.join(out, rec, "replay", "figures.json")) if last == "replay" else {}
    bursts = read_bursts(os.path.join(out, rec, "estimate", "bursts.csv"))

    def put(column, value, digits=4):
        if value is not None:
            row[column] = f"{value:.{digits}g}"

    put("frames", figure(estimate, "frames"), 9)
    put("bursts", float(len(bursts)), 9)
    put("estimate_fps", figure(estimate, "fps"))
    put("estimate_ms", figure(estimate, "estimate_ms"))
    put("replay_fps", figure(replay, "fps"))
    put("sun_half_width", figure(estimate, "lighting/interval/sun_half_width"))
    put("sky_half_width", figure(estimate, "lighting/interval/sky_half_width"))
    put("p90_worst_channel_error", figure(estimate, "lighting/p90_worst_channel_error"))
    put("interval_held_bursts", figure(estimate, "lighting/interval/covered_bursts"), 9)
    put("interval_bursts", figure(estimate, "lighting/interval/bursts"), 9)
    put("frames_held", figure(estimate, "lighting/frames_held"), 9)
    worst = [(burst_worst_error(b), b.get("burst", "")) for b in bursts]
    worst = [w for w in worst if w[0] is not None]
    if worst:
        error, burst = max(worst)
        put("worst_burst_error", error)
        row["worst_burst"] = burst
    return row, bursts


def csv_text(columns, rows):
    text = io.StringIO()
    writer = csv.DictWriter(text, fieldnames=columns, lineterminator="\n", extrasaction="ignore")
    writer.writeheader()
    for r in rows:
        writer.writerow(r)
    return text.getvalue().encode()


def plot(path, rows, bursts_by_recording):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    names = [r["recording"] for r in rows]
    fig, axes = plt.subplots(2, 1, figsize=(max(8.0, 1.2 * len(names) + 2), 7), sharex=True)
    fig.suptitle("per recording and burst: the 90% interval's half-width (bars, mean over R, G, B)\n"
                 "and the error against truth where there is one (dots, worst channel)", fontsize=10)
    for ax, quantity, title in ((axes[0], "sun", "E_sun"), (axes[1], "sky", "E_sky")):
        ax.set_ylabel(f"{title}, relative (%)")
        for i, r in enumerate(rows):
            bursts = bursts_by_recording.get(r["recording"], [])
            if r["status"] != "ok":
                ax.text(i, 0, f"failed:\n{r['failed_step']}", ha="center", va="bottom", color="firebrick", fontsize=8)
                continue
            n = max(len(bursts), 1)
            for k, b in enumerate(bursts):
                x = i - 0.35 + 0.7 * (k + 0.5) / n
                width = burst_half_width(b, quantity)
                if width is not None:
                    ax.bar(x, 100 * width, width=0.6 / n, color="lightsteelblue", edgecolor="steelblue")
                errors = burst_errors(b, (quantity,))
                if errors:
                    ax.plot(x, 100 * max(errors), "o", color="black", markersize=4)
        ax.grid(axis="y", alpha=0.3)
        ax.set_xlim(-0.6, len(names) - 0.4)
        ax.set_ylim(bottom=0)
    axes[1].set_xticks(range(len(names)))
    axes[1].set_xticklabels(names, rotation=30, ha="right")
    fig.tight_layout()
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    write_atomically(path, buffer.getvalue())


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--last", choices=STEPS[2:], default="replay")
    parser.add_argument("--incomplete", action="store_true")
    parser.add_argument("recordings", nargs="+")
    args = parser.parse_args()

    rows, burst_rows, bursts_by_recording = [], [], {}
    burst_columns = ["recording"]
    for rec in args.recordings:
        row, bursts = recording_row(args.out, rec, args.last, args.incomplete)
        rows.append(row)
        bursts_by_recording[rec] = bursts
        for b in bursts:
            for column in b:
                if column not in burst_columns:
                    burst_columns.append(column)
            burst_rows.append({"recording": rec, **b})
    os.makedirs(args.out, exist_ok=True)
    write_atomically(os.path.join(args.out, "results.csv"), csv_text(COLUMNS, rows))
    write_atomically(os.path.join(args.out, "bursts.csv"), csv_text(burst_columns, burst_rows))
    plot(os.path.join(args.out, "summary.png"), rows, bursts_by_recording)
    failed = [r for r in rows if r["status"] != "ok"]
    print(f"batch: {len(rows) - len(failed)} of {len(rows)} recordings done; "
          f"{os.path.join(args.out, 'results.csv')}", file=sys.stderr)
    for r in failed:
        print(f"batch: {r['recording']} failed at {r['failed_step']}: {r['reason']}", file=sys.stderr)
    return 0


if __name__ == "__main__":
    sys.exit(main())
