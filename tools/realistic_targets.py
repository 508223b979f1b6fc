#!/usr/bin/env python3
"""Prints the realistic fleet's targets for a campaign output directory (armfault run ... -o DIR).

Usage: tools/realistic_targets.py DIR [--check-a90-95 FAMILY:BOUND:min|max ...]

Per family and joint: detection, family+joint isolation and median latency; overall false
alarms over the healthy runs; friction factor >= 1.5 per joint (rate, median latency); K_T
factor 0.9 detection; median relative magnitude error for K_T and friction; runs not ok.
With DIR/tuning.json (from `armfault tune DIR`): each family's a90/95, the magnitude detected
90 % of the time at 95 % confidence. --check-a90-95 FAMILY:BOUND:min|max exits 1 unless that
family's a90/95 magnitude is at least (min) or at most (max) BOUND.
Reads only DIR/results.jsonl and DIR/tuning.json (standard library only).
"""
import collections
import json
import os
import statistics
import sys


def median(xs):
    return statistics.median(xs) if xs else float("nan")


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    path = sys.argv[1] + "/results.jsonl"
    runs = [json.loads(line) for line in open(path)]
    failed = [r for r in runs if r["status"] != "ok"]
    runs = [r for r in runs if r["status"] == "ok"]
    healthy = [r for r in runs if not r.get("family")]
    faulty = [r for r in runs if r.get("family")]

    def isolated(r):
        return r["detected"] and r["isolated_family"] == r["family"] and r["isolated_joint"] == r["joint"]

    print(f"runs {len(runs) + len(failed)}, failed {len(failed)}")
    for r in failed[:5]:
        print("  failed:", r["run_id"], r.get("failure_reason", ""))
    fa = sum(r["detected"] or r["alarm_before_onset"] for r in healthy)
    print(f"false alarms: {fa}/{len(healthy)} healthy runs")
    fa_faulty = sum(r["alarm_before_onset"] for r in faulty)
    print(f"alarms before onset in fault runs: {fa_faulty}/{len(faulty)}")
    det = sum(r["detected"] for r in faulty)
    iso = sum(isolated(r) for r in faulty)
    print(f"detection: {det}/{len(faulty)} = {det / max(1, len(faulty)):.3f}")
    print(f"isolation (family+joint) over all fault runs: {iso}/{len(faulty)} = {iso / max(1, len(faulty)):.3f}")
    print(f"isolation over detected runs: {iso}/{det} = {iso / max(1, det):.3f}")

    groups = collections.defaultdict(list)
    for r in faulty:
        groups[(r["family"], r["joint"])].append(r)
    print("\nfamily joint: detected / runs, isolated, median latency [s]")
    for (fam, j), rs in sorted(groups.items()):
        lat = [r["latency_s"] for r in rs if r.get("latency_s") is not None]
        wrong = collections.Counter(
            f'{r["isolated_family"]}@{r["isolated_joint"]}' for r in rs if r["detected"] and not isolated(r))
        print(f"  {fam:22s} j{j}: {sum(r['detected'] for r in rs):3d}/{len(rs):3d}, iso {sum(isolated(r) for r in rs):3d}, "
              f"lat {median(lat):.2f}  {dict(wrong) if wrong else ''}")

    print("\nfriction_factor >= 1.5 per joint: detected, median latency [s]")
    for j in sorted({r["joint"] for r in faulty}):
        rs = [r for r in faulty if r["family"] == "friction_increase" and r["joint"] == j and r["magnitude"] >= 1.5]
        if not rs:
            continue
        lat = [r["latency_s"] for r in rs if r.get("latency_s") is not None]
        print(f"  j{j}: {sum(r['detected'] for r in rs)}/{len(rs)} = {sum(r['detected'] for r in rs) / len(rs):.3f}, "
              f"median latency {median(lat):.2f}")
    kt = [r for r in faulty if r["family"] == "kt_degradation" and abs(r["magnitude"] - 0.9) < 1e-9]
    if kt:
        print(f"K_T 0.9: detected {sum(r['detected'] for r in kt)}/{len(kt)} = {sum(r['detected'] for r in kt) / len(kt):.3f}")
    for fam, name in (("kt_degradation", "kt_factor"), ("friction_increase", "friction_factor")):
        errs = [abs(r["magnitude_estimate"] - r["magnitude"]) / r["magnitude"] for r in faulty
                if r["family"] == fam and isolated(r) and r.get("magnitude_estimate") is not None
                and r.get("magnitude_name") == name]
        if errs:
            print(f"{fam}: median relative magnitude error {median(errs):.3f} over {len(errs)} isolated runs")

    status = 0
    tuning_path = sys.argv[1] + "/tuning.json"
    a90_95 = {}
    if os.path.exists(tuning_path):
        tuning = json.load(open(tuning_path))
        for fam, pod in sorted(tuning["detection_probability"].items()):
            fit = pod.get("fit") or {}
            value = fit.get("a90_95") if fit.get("ok") else None
            a90_95[fam] = value["magnitude"] if value else None
            print(f"a90/95 {fam}: {pod['magnitude_key']} = {a90_95[fam] if value else 'not reached in the tested range'}")
    checks = sys.argv[sys.argv.index("--check-a90-95") + 1:] if "--check-a90-95" in sys.argv else []
    for check in checks:
        fam, bound, kind = check.split(":")
        value = a90_95.get(fam)
        ok = value is not None and (value >= float(bound) if kind == "min" else value <= float(bound))
        print(f"check a90/95 {fam} {'>=' if kind == 'min' else '<='} {bound}: {'met' if ok else 'MISSED'} ({value})")
        status = status if ok else 1
    return status


if __name__ == "__main__":
    sys.exit(main())
