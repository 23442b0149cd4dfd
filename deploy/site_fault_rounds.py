#!/usr/bin/env python3
"""Rounds of the site on its own hosts with seeded random faults between the hosts (issue 34: "over
>= 100 with network faults injected between hosts"; docs/site.md, "The site on its own hosts").

  site_fault_rounds.py BIN SITE OUT [--rounds N] [--seed S] [--jobs J] [--security DIR] [--until-done S]

Each round r runs deploy/site_hosts.sh once (every crane's whole stack on a host of its own, the
site service on another; network namespaces joined by a bridge) with the job set of seed S + r and
faults drawn from seed S + r, as the issue lists them:
  - a full partition of one host (a crane's or the service's) for 5-30 s;
  - packet loss of 0-30 % to and from one host for 10-30 s (tc netem, else nftables);
  - a delay of 0-200 ms each way to and from one host for 10-30 s (tc netem, else crane_packet_delay);
  - with probability 0.5, the site service killed with -9 and started again 1-10 s later;
  - with probability 0.25, a crane's host stopped for good, and the site operator's word that it is
    out of service 10 s later (crane_site_status --out-of-service);
each starting 5-45 s after every crane is ready. It prints one line per round (exit status, the
closest distance the site office heard, the reactions to lost links, the reason of a failure) and
then the distributions over the rounds. A round passes when site_hosts.sh exits 0: every job done
(or waiting at rest for a stopped crane), no crane braked, the closest distance the office heard at
or above the site's stop margin.

The closest distance here is the office's, from the cranes' reports at 10 Hz (crane_site_status),
not the true distance of the lockstep (crane_site demo). Each round takes 30-100 s and two whole
stacks in real time: on a small machine the stalls of the stacks fail rounds (docs/site.md).

Exit status: 0 when every round passed; 1 when one did not; 2 for bad usage.
"""
import argparse
import os
import random
import re
import statistics
import subprocess
import sys
import time


def draw_faults(rng, hosts, cranes):
    """The faults of one round, as site_hosts.sh --fault specs (whole seconds after ready)."""
    start = lambda: rng.randint(5, 45)
    faults = [
        "partition:%s:%d:%d" % (rng.choice(hosts), start(), rng.randint(5, 30)),
        "loss:%s:%d:%d:%d" % (rng.choice(hosts), rng.randint(0, 30), start(), rng.randint(10, 30)),
        "delay:%s:%d:%d:%d" % (rng.choice(hosts), rng.randint(0, 200), start(), rng.randint(10, 30)),
    ]
    if rng.random() < 0.5:
        faults.append("kill-service:%d:%d" % (start(), rng.randint(1, 10)))
    if rng.random() < 0.25:
        crane, at = rng.choice(cranes), start()
        faults += ["stop-host:%s:%d" % (crane, at), "out-of-service:%s:%d" % (crane, at + 10)]
    return faults


def crane_names(bin_dir, site):
    text = subprocess.run([os.path.join(bin_dir, "crane_site"), "check", "--site", site], capture_output=True,
                          text=True, check=True).stdout
    names = []
    for line in text.splitlines():
        fields = line.split()
        if len(fields) > 2 and re.match(r"^[0-9.]+$", fields[2]):
            names += [fields[0], fields[1]]
    return sorted(set(names)) or sys.exit("site_fault_rounds: no cranes in 'crane_site check --site %s'" % site)


def quantile(values, q):
    """Nearest rank, as crane_site demo prints its distributions."""
    ordered = sorted(values)
    return ordered[min(len(ordered) - 1, max(0, int(-(-q * len(ordered) // 1)) - 1))] if ordered else float("nan")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("bin")
    parser.add_argument("site")
    parser.add_argument("out")
    parser.add_argument("--rounds", type=int, default=10)
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--jobs", type=int, default=1)
    parser.add_argument("--until-done", type=int, default=400)
    parser.add_argument("--security")
    args = parser.parse_args()
    if args.rounds < 1:
        parser.error("--rounds must be >= 1")
    here = os.path.dirname(os.path.realpath(__file__))
    cranes = crane_names(args.bin, args.site)
    hosts = cranes + ["site"]
    closest, reactions, failed = [], [], []
    os.makedirs(args.out, exist_ok=True)
    print("round  seed  exit  wall_s  closest_m  reactions_ms  faults")
    for r in range(args.rounds):
        seed = args.seed + r
        faults = draw_faults(random.Random(seed), hosts, cranes)
        out = os.path.join(args.out, "round_%03d" % r)
        command = ["bash", os.path.join(here, "site_hosts.sh"), args.bin, args.site, out, "--jobs", str(args.jobs),
                   "--seed", str(seed), "--until-done", str(args.until_done)]
        if args.security:
            command += ["--security", args.security]
        for f in faults:
            command += ["--fault", f]
        began = time.monotonic()
        run = subprocess.run(command, capture_output=True, text=True)
        wall = time.monotonic() - began
        with open(out + ".log", "w") as log:
            log.write(run.stdout + run.stderr)
        found = re.search(r"closest reported distance ([0-9.]+) m", run.stdout)
        if found:
            closest.append(float(found.group(1)))
        these = [float(x) for line in re.findall(r"link losses: reactions \[ms\] ([0-9 .]+)", run.stdout)
                 for x in line.split()]
        reactions += these
        why = [line[len("FAILED: "):] for line in run.stdout.splitlines() if line.startswith("FAILED: ")]
        why += [line for line in (run.stdout + run.stderr).splitlines() if line.startswith("site_hosts.sh: ")]
        if run.returncode != 0:
            failed.append((r, why[0] if why else "exit %d" % run.returncode))
        print("%5d %5d %5d %7.1f %10s  %-12s  %s%s" % (r, seed, run.returncode, wall, found.group(1) if found else "-",
                                                  " ".join("%.0f" % x for x in these) or "-", " ".join(faults),
                                                  ("  FAILED: " + why[0]) if run.returncode != 0 and why else ""))
        sys.stdout.flush()
    print("\n%d rounds, %d passed" % (args.rounds, args.rounds - len(failed)))
    if closest:
        print("closest distance the office heard [m]: min %.3f  median %.3f  (%d rounds)" %
              (min(closest), statistics.median(closest), len(closest)))
    if reactions:
        print("reaction, link lost -> crane safe [ms]: min %.0f  median %.0f  p90 %.0f  max %.0f  (%d losses)" %
              (min(reactions), quantile(reactions, 0.5), quantile(reactions, 0.9), max(reactions), len(reactions)))
    for r, why in failed:
        print("round %d failed: %s" % (r, why))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
