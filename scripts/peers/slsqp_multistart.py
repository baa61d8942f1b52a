#!/usr/bin/env python3
"""scipy's SLSQP from every start of a plyscape multistart: the "tight
SLSQP loop" beside which `docs/exploration.md` sets plyscape's runs.

The starts are read from the `x0_*` columns of the multistart's
`runs.csv`, so both tools begin at the same designs. The problem is one of
`slsqp_hs.py`'s (written there exactly as the Rust code states it: the
constraints g_j(x) <= 0 with the same scales, the same box). Each run uses
ftol 1e-12 and the exact gradients, and is counted as plyscape counts
(`optimize::Counted`): one evaluation gives f and every g, so the function
calls are scipy's `nfev` and the gradient calls its `njev`.

Each row gives scipy's own verdict (`success`) and whether the end is at
the published optimum (`at_optimum`: feasible to 1e-6 in max g and f
within 1e-6 of f*, relative to max(|f*|, 1)); SLSQP often ends there with
"Positive directional derivative for linesearch" and success False. The
last row sums the calls and counts both.

Usage (a virtual environment with scipy):
    python3 -m venv .venv && .venv/bin/pip install scipy
    .venv/bin/python scripts/peers/slsqp_multistart.py hs100 \
        results/hs100_multistart/runs.csv > results/hs100_multistart/slsqp.csv
"""
import csv
import os
import sys

import scipy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from slsqp_hs import CASES, run  # noqa: E402


def starts(path):
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    header, body = rows[0], rows[1:]
    cols = [i for i, h in enumerate(header) if h.startswith("x0_")]
    return [[float(r[i]) for i in cols] for r in body]


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: slsqp_multistart.py <problem> <runs.csv>")
    name, path = sys.argv[1], sys.argv[2]
    case = next((c for c in CASES if c[0] == name), None)
    if case is None:
        sys.exit(f"unknown problem {name!r}; known: {', '.join(c[0] for c in CASES)}")
    _, kernel, bounds, _, fstar = case
    out = sys.stdout
    out.write(f"# scipy {scipy.__version__} SLSQP, ftol 1e-12, {name} from the starts of {path}\n")
    out.write("start,f,rel_error,max_g,function_calls,gradient_calls,success,at_optimum,message\n")
    nf = ng = ok = won = 0
    for k, x0 in enumerate(starts(path)):
        r = run(kernel, bounds, x0)
        err = abs(r.fun - fstar) / max(abs(fstar), 1.0)
        max_g = max(kernel(r.x)[1])
        good = max_g <= 1e-6 and err <= 1e-6
        nf, ng, ok, won = nf + r.nfev, ng + r.njev, ok + good, won + bool(r.success)
        out.write(f"{k},{float(r.fun)!r},{err:.3e},{max_g:.3e},{r.nfev},{r.njev},"
                  f"{r.success},{good},{r.message}\n")
    out.write(f"all,,,,{nf},{ng},{won},{ok},\n")


if __name__ == "__main__":
    main()
