"""What a monitor written in Python costs (docs/monitor-api.md, "Python", "Cost").

    PYTHONPATH=build/python /usr/bin/python3 python/bench/bench_python_monitor.py [--cli build/armfault]

1. Per tick: armfault.replay() feeds a recorded 10 s run (5001 ticks) to a monitor through the
   same call path as a campaign (the tick kept, the Signals arrays refilled, step() called and its
   return read, the GIL taken once per 256 ticks); best of 7, in microseconds per tick, for the
   trivial monitor
   (armfault.Monitor: step returns None) and the example (python/examples/torque_ratio_monitor.py).
2. A campaign: python/bench/campaign-200.json (200 runs of 10 s at 500 Hz, 1.0e6 ticks) on 2
   threads: `armfault run -j 2` (the built-in monitor, for reference), then run_campaign with the
   built-in monitor, the trivial one and the example (and the example on 1 thread). Wall time and
   CPU time (all threads) each.
"""
import argparse
import os
import pathlib
import resource
import subprocess
import sys
import tempfile
import time

import armfault

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent / "examples"))
from torque_ratio_monitor import TorqueRatioMonitor  # noqa: E402

CAMPAIGN = HERE / "campaign-200.json"


def per_tick(monitor, trace, repeat=7):
    best = float("inf")
    for _ in range(repeat):
        start = time.perf_counter()
        armfault.replay(monitor, trace)
        best = min(best, time.perf_counter() - start)
    return best / len(trace.t_s) * 1e6


def timed(what, f):
    wall, cpu = time.perf_counter(), time.process_time()
    children = resource.getrusage(resource.RUSAGE_CHILDREN)
    result = f()
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = time.process_time() - cpu + (after.ru_utime + after.ru_stime) - (children.ru_utime + children.ru_stime)
    wall = time.perf_counter() - wall
    print(f"  {what:58s} {wall:7.1f} s wall  {cpu:7.1f} s CPU", flush=True)
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default=str(HERE.parents[1] / "build" / "armfault"))
    parser.add_argument("--skip-campaign", action="store_true")
    args = parser.parse_args()

    campaign = armfault.load_campaign(CAMPAIGN)
    trace = armfault.simulate(campaign, 0)
    print(f"per tick (replay of {trace.run_id!r}, {len(trace.t_s)} ticks, best of 7):")
    for name, monitor in [("trivial (armfault.Monitor)", armfault.Monitor), ("example (TorqueRatioMonitor)", TorqueRatioMonitor)]:
        print(f"  {name:30s} {per_tick(monitor, trace):6.2f} us/tick", flush=True)
    if args.skip_campaign:
        return
    print(f"campaign {campaign.name}: {len(campaign)} runs of {campaign.duration_s:g} s, 2 cores "
          f"(load average {os.getloadavg()[0]:.1f} at the start):")
    with tempfile.TemporaryDirectory() as tmp:
        timed("armfault run -j 2 (built-in monitor)",
              lambda: subprocess.run([args.cli, "run", str(CAMPAIGN), "-o", tmp + "/cli", "-q", "-j", "2"],
                                     check=False, capture_output=True))
        timed("run_campaign(threads=2) (built-in monitor)", lambda: armfault.run_campaign(campaign, threads=2))
        timed("run_campaign(threads=2, monitor=armfault.Monitor)",
              lambda: armfault.run_campaign(campaign, threads=2, monitor=armfault.Monitor))
        records = timed("run_campaign(threads=2, monitor=TorqueRatioMonitor)",
                        lambda: armfault.run_campaign(campaign, threads=2, monitor=TorqueRatioMonitor))
        timed("run_campaign(threads=1, monitor=TorqueRatioMonitor)",
              lambda: armfault.run_campaign(campaign, threads=1, monitor=TorqueRatioMonitor))
    s = armfault.summary(records, campaign)["overall"]
    print(f"  (the example: detection {s['detection']['rate']:.2f}, false alarms {s['false_alarm']['rate']:.2f}, "
          f"{s['latency']['median_s']:.2f} s median latency)")


if __name__ == "__main__":
    main()
