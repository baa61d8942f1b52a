#!/usr/bin/env python3
"""pymoo's NSGA-II on the analytic fronts of plyscape's studies (ZDT1,
ZDT2, ZDT3 and DTLZ2), at the studies' budgets, scored beside plyscape's
committed fronts by one set of formulas.

Budgets as in studies/zdt1.toml, zdt2.toml, zdt3.toml (population 100,
20 000 evaluations) and dtlz2.toml (population 300, 60 000), pymoo's
NSGA-II defaults otherwise (SBX crossover eta 20, probability 0.9; polynomial
mutation eta 20, set explicitly: the operators and indices of
plyscape's NSGA-II, docs/guide.md).
Seeds 1..SEEDS; the table gives the median and the range over them.

Scoring, for every row (pymoo's runs and the rows of plyscape's
results/<study>/front.csv): the non-dominated points of the front;
hypervolume to the reference point 1.1 in every objective (exact, by
slicing, as `optimize::indicators`); IGD to the analytic front sampled as
`optimize::mo_testproblems` samples it (1000 points evenly in f1 for ZDT1
and ZDT2, the non-dominated ones of 10 000 for ZDT3, the 496 directions
of the simplex lattice with 30 divisions scaled to unit length for
DTLZ2).

Usage (a virtual environment with pymoo):
    python3 -m venv .venv && .venv/bin/pip install pymoo
    .venv/bin/python scripts/peers/pymoo_fronts.py > results/front_peers/pymoo.csv
"""
import csv
import statistics
import sys

import numpy as np
import pymoo
from pymoo.algorithms.moo.nsga2 import NSGA2
from pymoo.operators.crossover.sbx import SBX
from pymoo.operators.mutation.pm import PM
from pymoo.optimize import minimize
from pymoo.problems import get_problem

SEEDS = 10
STUDIES = [
    # name, pymoo problem, population, evaluations, objectives
    ("zdt1", ("zdt1", {}), 100, 20000, 2),
    ("zdt2", ("zdt2", {}), 100, 20000, 2),
    ("zdt3", ("zdt3", {}), 100, 20000, 2),
    ("dtlz2", ("dtlz2", {"n_var": 12, "n_obj": 3}), 300, 60000, 3),
]


def non_dominated(points):
    """The non-dominated points (minimization), equal points once."""
    pts = sorted(set(tuple(p) for p in points))
    if len(pts[0]) == 2:
        keep, best = [], float("inf")
        for p in pts:  # sorted by f1, then f2
            if p[1] < best:
                keep.append(p)
                best = p[1]
        return keep
    a = np.array(pts)
    keep = []
    for i, p in enumerate(a):
        le = np.all(a <= p, axis=1) & np.any(a < p, axis=1)
        if not le.any():
            keep.append(tuple(pts[i]))
    return keep


def zdt_front(n, h):
    return [(i / (n - 1), h(i / (n - 1))) for i in range(n)]


def analytic(name):
    if name == "zdt1":
        return zdt_front(1000, lambda f: 1.0 - np.sqrt(f))
    if name == "zdt2":
        return zdt_front(1000, lambda f: 1.0 - f * f)
    if name == "zdt3":
        h = lambda f: 1.0 - np.sqrt(f) - f * np.sin(10.0 * np.pi * f)
        return non_dominated(zdt_front(10000, h))
    lattice = [
        (i / 30, j / 30, (30 - i - j) / 30)
        for i in range(31)
        for j in range(31 - i)
    ]
    return [tuple(np.array(w) / np.linalg.norm(w)) for w in lattice]


def hv2(points, r):
    p = sorted((a for a in points if a[0] < r[0] and a[1] < r[1]))
    hv, level = 0.0, r[1]
    for x, y in p:
        if y < level:
            hv += (r[0] - x) * (level - y)
            level = y
    return hv


def hypervolume(points, r):
    if len(r) == 2:
        return hv2(points, r)
    p = sorted((a for a in points if all(x < y for x, y in zip(a, r))), key=lambda a: a[2])
    hv = 0.0
    for k, a in enumerate(p):
        top = p[k + 1][2] if k + 1 < len(p) else r[2]
        if top > a[2]:
            hv += (top - a[2]) * hv2([(b[0], b[1]) for b in p[: k + 1]], r[:2])
    return hv


def igd(points, reference):
    a = np.array(points)
    return float(np.mean([np.min(np.linalg.norm(a - np.array(r), axis=1)) for r in reference]))


def score(name, points, m):
    front = non_dominated(points)
    return len(front), hypervolume(front, [1.1] * m), igd(front, analytic(name))


def ours(name, m):
    """plyscape's committed fronts, one entry per method."""
    rows = list(csv.DictReader(open(f"results/{name}/front.csv")))
    cols = ["f1", "f2", "f3"][:m]
    by = {}
    for row in rows:
        by.setdefault(row["method"], []).append(tuple(float(row[c]) for c in cols))
    return by


def main():
    out = csv.writer(sys.stdout, lineterminator="\n")
    out.writerow(["problem", "source", "method", "runs", "evaluations", "points",
                  "hypervolume", "hypervolume_min", "hypervolume_max",
                  "igd_analytic", "igd_min", "igd_max", "pymoo"])
    for name, (pname, kw), pop, evals, m in STUDIES:
        problem = get_problem(pname, **kw)
        scores = []
        for seed in range(1, SEEDS + 1):
            res = minimize(problem, NSGA2(pop_size=pop, crossover=SBX(prob=0.9, eta=20),
                                  mutation=PM(eta=20)), ("n_eval", evals),
                           seed=seed, verbose=False)
            scores.append(score(name, res.F.tolist(), m))
        pts, hv, d = zip(*scores)
        out.writerow([name, "pymoo", "nsga2", SEEDS, evals, statistics.median(pts),
                      statistics.median(hv), min(hv), max(hv),
                      statistics.median(d), min(d), max(d), pymoo.__version__])
        for method, points in ours(name, m).items():
            n, hv, d = score(name, points, m)
            out.writerow([name, "plyscape", method, 1, "", n, hv, hv, hv, d, d, d, ""])
        sys.stdout.flush()


if __name__ == "__main__":
    main()
