#!/usr/bin/env python3
"""scipy's SLSQP on the Hock-Schittkowski problems of plyscape's
`optimize::testproblems` (and HS 22 of `explore`), written here exactly as
the Rust code states them: constraints g_j(x) <= 0 with the same
normalising scales, the same boxes, the same starts. One run per problem,
ftol 1e-12, the exact gradients.

Counting as plyscape counts (`optimize::Counted`): one evaluation gives f
and every g, so the function calls are scipy's objective evaluations
(`nfev`) and the gradient calls its Jacobian evaluations (`njev`).

Usage (a virtual environment with scipy):
    python3 -m venv .venv && .venv/bin/pip install scipy
    .venv/bin/python scripts/peers/slsqp_hs.py > results/sqp_peers/slsqp.csv
"""
import sys

import numpy as np
import scipy
from scipy.optimize import minimize


def hs21(x):
    f = 0.01 * x[0] ** 2 + x[1] ** 2 - 100.0
    g = [-(10.0 * x[0] - x[1] - 10.0) / 10.0]
    return f, g, [0.02 * x[0], 2.0 * x[1]], [[-1.0, 0.1]]


def hs35(x):
    a, b, c = x
    f = 9 - 8 * a - 6 * b - 4 * c + 2 * a * a + 2 * b * b + c * c + 2 * a * b + 2 * a * c
    gf = [-8 + 4 * a + 2 * b + 2 * c, -6 + 4 * b + 2 * a, -4 + 2 * c + 2 * a]
    return f, [-(3 - a - b - 2 * c) / 3.0], gf, [[1 / 3, 1 / 3, 2 / 3]]


def hs43(x):
    a, b, c, d = x
    f = a * a + b * b + 2 * c * c + d * d - 5 * a - 5 * b - 21 * c + 7 * d
    gf = [2 * a - 5, 2 * b - 5, 4 * c - 21, 2 * d + 7]
    c1 = 8 - a * a - b * b - c * c - d * d - a + b - c + d
    c2 = 10 - a * a - 2 * b * b - c * c - 2 * d * d + a + d
    c3 = 5 - 2 * a * a - b * b - c * c - 2 * a + b + d
    gg = [
        [(2 * a + 1) / 8, (2 * b - 1) / 8, (2 * c + 1) / 8, (2 * d - 1) / 8],
        [(2 * a - 1) / 10, 4 * b / 10, 2 * c / 10, (4 * d - 1) / 10],
        [(4 * a + 2) / 5, (2 * b - 1) / 5, 2 * c / 5, -1 / 5],
    ]
    return f, [-c1 / 8, -c2 / 10, -c3 / 5], gf, gg


def hs76(x):
    a, b, c, d = x
    f = a * a + 0.5 * b * b + c * c + 0.5 * d * d - a * c + c * d - a - 3 * b + c - d
    gf = [2 * a - c - 1, b - 3, 2 * c - a + d + 1, d + c - 1]
    g = [-(5 - a - 2 * b - c - d) / 5, -(4 - 3 * a - b - 2 * c + d) / 4, -(b + 4 * c - 1.5) / 1.5]
    gg = [[0.2, 0.4, 0.2, 0.2], [0.75, 0.25, 0.5, -0.25], [0.0, -1 / 1.5, -4 / 1.5, 0.0]]
    return f, g, gf, gg


def hs100(x):
    x1, x2, x3, x4, x5, x6, x7 = x
    f = ((x1 - 10) ** 2 + 5 * (x2 - 12) ** 2 + x3 ** 4 + 3 * (x4 - 11) ** 2 + 10 * x5 ** 6
         + 7 * x6 * x6 + x7 ** 4 - 4 * x6 * x7 - 10 * x6 - 8 * x7)
    gf = [2 * (x1 - 10), 10 * (x2 - 12), 4 * x3 ** 3, 6 * (x4 - 11), 60 * x5 ** 5,
          14 * x6 - 4 * x7 - 10, 4 * x7 ** 3 - 4 * x6 - 8]
    c1 = 127 - 2 * x1 * x1 - 3 * x2 ** 4 - x3 - 4 * x4 * x4 - 5 * x5
    c2 = 282 - 7 * x1 - 3 * x2 - 10 * x3 * x3 - x4 + x5
    c3 = 196 - 23 * x1 - x2 * x2 - 6 * x6 * x6 + 8 * x7
    c4 = -4 * x1 * x1 - x2 * x2 + 3 * x1 * x2 - 2 * x3 * x3 - 5 * x6 + 11 * x7
    gg = [
        [4 * x1 / 127, 12 * x2 ** 3 / 127, 1 / 127, 8 * x4 / 127, 5 / 127, 0, 0],
        [7 / 282, 3 / 282, 20 * x3 / 282, 1 / 282, -1 / 282, 0, 0],
        [23 / 196, 2 * x2 / 196, 0, 0, 0, 12 * x6 / 196, -8 / 196],
        [(8 * x1 - 3 * x2) / 10, (2 * x2 - 3 * x1) / 10, 4 * x3 / 10, 0, 0, 0.5, -1.1],
    ]
    return f, [-c1 / 127, -c2 / 282, -c3 / 196, -c4 / 10], gf, gg


def hs22(x):
    f = (x[0] - 2) ** 2 + (x[1] - 1) ** 2
    g = [x[0] + x[1] - 2, x[0] ** 2 - x[1]]
    return f, g, [2 * (x[0] - 2), 2 * (x[1] - 1)], [[1, 1], [2 * x[0], -1]]


# name, kernel, box, start, f* (Hock & Schittkowski 1981, as the Rust docs cite)
CASES = [
    ("hs21", hs21, [(2, 50), (-50, 50)], [2, -1], -99.96),
    ("hs35", hs35, [(0, 10)] * 3, [0.5, 0.5, 0.5], 1 / 9),
    ("hs43", hs43, [(-10, 10)] * 4, [0, 0, 0, 0], -44.0),
    ("hs76", hs76, [(0, 10)] * 4, [0.5] * 4, -103 / 22),
    ("hs100", hs100, [(-10, 10)] * 7, [1, 2, 0, 4, 0, 1, 1], 680.6300573),
    ("hs22", hs22, [(-5, 5)] * 2, [2, 2], 1.0),
]


def run(kernel, bounds, x0):
    fun = lambda x: kernel(x)[0]
    jac = lambda x: np.array(kernel(x)[2], dtype=float)
    cons = {
        "type": "ineq",  # scipy: c(x) >= 0, so c = -g
        "fun": lambda x: -np.array(kernel(x)[1], dtype=float),
        "jac": lambda x: -np.array(kernel(x)[3], dtype=float),
    }
    return minimize(fun, np.array(x0, float), jac=jac, bounds=bounds, constraints=[cons],
                    method="SLSQP", options={"ftol": 1e-12, "maxiter": 200})


def main():
    out = sys.stdout
    out.write(f"# scipy {scipy.__version__} SLSQP, ftol 1e-12\n")
    out.write("problem,f,rel_error,max_g,function_calls,gradient_calls,success,message\n")
    for name, kernel, bounds, x0, fstar in CASES:
        r = run(kernel, bounds, x0)
        err = abs(r.fun - fstar) / max(abs(fstar), 1.0)
        max_g = max(kernel(r.x)[1])
        out.write(f"{name},{float(r.fun)!r},{err:.3e},{max_g:.3e},{r.nfev},{r.njev},{r.success},{r.message}\n")


if __name__ == "__main__":
    main()
