#!/usr/bin/env python3
"""flocsim's du/U_inf and F/F0 at the paper's normalised aggregate size, from two runs that bracket
it and their du = 0 baseline (docs/validation/comparison-points.md).

ln(<n_a>/<n_a>0) is taken linear in du between the two runs (aggregate size grows about
exponentially with the well depth over such a bracket), and F/F0 linear in ln(<n_a>/<n_a>0) between
them. The errors are the runs' batch-means errors carried through both interpolations (the
baseline's enters both ratios of a run, and both runs, so it is carried once, correlated); the
error of the interpolation's shape over the bracket is not in them.

Usage: scripts/comparison-interpolate.py TARGET LOW.json HIGH.json BASELINE.json [STATED_DU]
  TARGET       the paper's <n_a>/<n_a>0 (2.3 at phi 0.12, 7.6 at phi 0.20)
  STATED_DU    the paper's du/U_inf at that size: prints the factor du*/STATED_DU"""
import json, math, sys


def observables(path):
    r = json.load(open(path))
    return r['case']['du_over_Uinf'], r['observables']


def estimate(target, du, F, n, F0, n0):
    """du* and F/F0 at ln(n/n0) = ln(target), for the two runs (lists of two)."""
    l = [math.log(n[k] / n0) for k in range(2)]
    s = (math.log(target) - l[0]) / (l[1] - l[0])
    ff = [F[k] / F0 for k in range(2)]
    return du[0] + s * (du[1] - du[0]), ff[0] + s * (ff[1] - ff[0]), s


def main(argv):
    if len(argv) not in (5, 6):
        sys.exit(__doc__)
    target = float(argv[1])
    runs = [observables(argv[2]), observables(argv[3])]
    _, base = observables(argv[4])
    du = [r[0] for r in runs]
    value = {'F': [r[1]['F']['mean'] for r in runs], 'n': [r[1]['n_a_mean']['mean'] for r in runs],
             'F0': base['F']['mean'], 'n0': base['n_a_mean']['mean']}
    error = {'F': [r[1]['F']['error'] for r in runs], 'n': [r[1]['n_a_mean']['error'] for r in runs],
             'F0': base['F']['error'], 'n0': base['n_a_mean']['error']}

    def at(v):
        return estimate(target, du, v['F'], v['n'], v['F0'], v['n0'])

    d_star, ff_star, s = at(value)
    ratios = [value['n'][k] / value['n0'] for k in range(2)]
    if not min(ratios) <= target <= max(ratios):
        print(f"warning: {target} is outside the bracket {ratios[0]:.3f}-{ratios[1]:.3f}: extrapolated")
    # linear error propagation by central differences, one input at a time
    var_d = var_f = 0.0
    for key in value:
        for k in (range(2) if isinstance(value[key], list) else [None]):
            e = error[key][k] if k is not None else error[key]
            up = json.loads(json.dumps(value)); down = json.loads(json.dumps(value))
            h = 1e-4 * (value[key][k] if k is not None else value[key])
            if k is None:
                up[key] += h; down[key] -= h
            else:
                up[key][k] += h; down[key][k] -= h
            (d1, f1, _), (d2, f2, _) = at(up), at(down)
            var_d += ((d1 - d2) / (2 * h) * e) ** 2
            var_f += ((f1 - f2) / (2 * h) * e) ** 2
    print(f"<n_a>/<n_a>0 at du {du[0]}: {ratios[0]:.3f}; at du {du[1]}: {ratios[1]:.3f}; "
          f"target {target} at fraction {s:.3f} of the bracket")
    print(f"du* = {d_star:.5f} +- {math.sqrt(var_d):.5f}   F/F0 at the target = {ff_star:.4f} +- {math.sqrt(var_f):.4f}")
    if len(argv) == 6:
        stated = float(argv[5])
        print(f"factor on du = du*/{stated} = {d_star / stated:.3f} +- {math.sqrt(var_d) / stated:.3f}")


if __name__ == '__main__':
    main(sys.argv)
