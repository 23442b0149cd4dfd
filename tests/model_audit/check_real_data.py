#!/usr/bin/env python3
"""The model audit on the real datasets of ../shared/data (recorded by others), as docs/model_audit.md
reports them: each run must name the documented cause, gain at least half the held-out error, and
give the main parameter within 10 % of the documented fit (a regression guard on the reported
figures, not a truth: these are measurements of real machines, whose truth nobody knows).

Usage: check_real_data.py CRANE_AUDIT DATA_DIR OUT_DIR. Exit 0 when both pass; skipped (exit 77)
when DATA_DIR is missing (a clone without shared/ beside it).
"""
import json
import pathlib
import subprocess
import sys

CASES = [
    # name, arguments, cause, parameter, documented value, documented gain [%] (of the model with
    # every cause named), documented second cause (stepwise)
    ("emps", ["--model", "axis", "--data", "emps/DATA_EMPS.csv", "--columns", "t=t_s,u=vir_V,x=qm_m",
              "--param", "K_m=0.37", "--param", "b=2.1", "--param", "c=0.21", "--calibrate"],
     "viscous_friction_asymmetry", "viscous_asymmetry", -0.4193, 85.8, "saturation"),
    ("pendulum_kaheman", ["--model", "pendulum", "--data", "pendulum_kaheman/SingleDataFreeSwing_1.csv",
                          "--columns", "t=t_s,theta=theta1_rad", "--param", "L=0.15",
                          "--param", "theta_zero=3.14159265358979", "--calibrate", "--t-max", "68"],
     "pendulum_coulomb_damping", "coulomb_damping", 0.1465, 88.0, "none"),
]


def main():
    audit, data, out = sys.argv[1], pathlib.Path(sys.argv[2]), pathlib.Path(sys.argv[3])
    if not data.is_dir():
        print(f"skipped: {data} is missing")
        return 77
    failures = 0
    for name, arguments, cause, parameter, value, gain, second in CASES:
        args = [a if not a.endswith(".csv") else str(data / a) for a in arguments]
        target = out / name
        run = subprocess.run([audit, *args, "--out", str(target)], capture_output=True, text=True)
        if run.returncode != 0:
            print(f"{name}: crane_audit failed ({run.returncode}): {run.stderr.strip()[-500:]}")
            failures += 1
            continue
        report = json.loads((target / "report.json").read_text())
        got = report["parameters"].get(parameter, {}).get("value", float("nan"))
        percent = report["gain"]["percent"]
        print(f"[ figure   ] {name}: cause {report['cause']}, {parameter} = {got:.4f} (documented {value}), "
              f"second cause {report.get('second_cause')} (documented {second}), "
              f"held-out gain {percent:.1f} % (documented {gain} %)")
        problems = []
        if report["cause"] != cause:
            problems.append(f"cause {report['cause']}, documented {cause}")
        if report.get("second_cause") != second:
            problems.append(f"second cause {report.get('second_cause')}, documented {second}")
        if not abs(got - value) <= 0.1 * abs(value):
            problems.append(f"{parameter} = {got} is not within 10 % of {value}")
        if not percent >= 50.0:
            problems.append(f"held-out gain {percent:.1f} % < 50 %")
        for p in problems:
            print(f"{name}: {p}")
        failures += bool(problems)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
