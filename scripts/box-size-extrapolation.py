#!/usr/bin/env python3
"""The finite-size extrapolation of docs/validation/stokes-limit.md: runs of one case in periodic
boxes of different size, the same phi, extrapolated to an unbounded suspension.

A periodic box confines each sphere's backflow; Hasimoto's series makes the correction to the
settling velocity grow with (V_sphere / V_box)^(1/3), i.e. with N^(-1/3) at fixed phi. So the
runs' U/U_inf (or --quantity) is fitted as

    y = y_inf - b N^(-1/3)

by weighted least squares (weights 1 / error^2, each run's batch-means error times
--error-scale). With two boxes the line is exact; with three or more chi^2 over the degrees of
freedom, and each run's residual in units of its error, test the form.

--check DOC fails unless DOC holds the table whole, row for row.

Usage: scripts/box-size-extrapolation.py [--quantity Q] [--error-scale F] [--check DOC] RESULT.json ..."""
import argparse
import json
import math
import sys


def fail(message):
    print(f'box-size-extrapolation.py: {message}', file=sys.stderr)
    sys.exit(1)


def load(name, quantity):
    try:
        with open(name) as f:
            r = json.load(f)
        n = int(r['derived']['sphere_count'])
        o = r['observables'][quantity]
        return {'file': name, 'N': n, 'L_over_a': float(r['case']['L_over_a']),
                'cells': 'x'.join(str(c) for c in r['derived']['box_cells']),
                'version': r.get('flocsim_version', '?'), 'y': float(o['mean']),
                'error': float(o['error'])}
    except (OSError, ValueError, KeyError, TypeError) as e:
        fail(f'{name}: not a suspension run\'s result.json with {quantity} ({e})')


def fit(points):
    """Weighted least squares of y = c + m x; returns c, m, their errors and chi^2."""
    w = [1 / p['e'] ** 2 for p in points]
    S = sum(w)
    Sx = sum(wi * p['x'] for wi, p in zip(w, points))
    Sy = sum(wi * p['y'] for wi, p in zip(w, points))
    Sxx = sum(wi * p['x'] ** 2 for wi, p in zip(w, points))
    Sxy = sum(wi * p['x'] * p['y'] for wi, p in zip(w, points))
    D = S * Sxx - Sx ** 2
    m = (S * Sxy - Sx * Sy) / D
    c = (Sxx * Sy - Sx * Sxy) / D
    chi2 = sum(wi * (p['y'] - c - m * p['x']) ** 2 for wi, p in zip(w, points))
    return c, m, math.sqrt(Sxx / D), math.sqrt(S / D), chi2


def table(runs, quantity, scale):
    points = [{'x': r['N'] ** (-1 / 3), 'y': r['y'], 'e': r['error'] * scale} for r in runs]
    c, m, ec, em, chi2 = fit(points)
    dof = len(points) - 2
    lines = [f'| L/a | cells | N | N^(-1/3) | {quantity} | error used | fit | residual / error | flocsim |',
             '|---|---|---|---|---|---|---|---|---|']
    for r, p in zip(runs, points):
        line = c + m * p['x']
        lines.append(f"| {r['L_over_a']:g} | {r['cells']} | {r['N']} | {p['x']:.3f} | {p['y']:.4f} | "
                     f"{p['e']:.4f} | {line:.4f} | {(p['y'] - line) / p['e']:+.2f} | {r['version']} |")
    lines.append(f'| N -> infinity | | | 0 | | | {c:.4f} +- {ec:.4f} | | |')
    chi = (f'chi^2 = {chi2:.2f} over {dof} degree{"s" if dof > 1 else ""} of freedom' if dof > 0
           else 'two boxes: the line is exact')
    lines.append('')
    lines.append(f'Slope b = {-m:.3f} +- {em:.3f} ({quantity} = y_inf - b N^(-1/3)); {chi}; '
                 f'errors are the runs\' batch-means errors times {scale:g}.')
    return lines


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--quantity', default='U_over_Uinf', help='an observable of result.json (default U_over_Uinf)')
    parser.add_argument('--error-scale', type=float, default=1.0,
                        help='multiply every run\'s error by this (batch-means errors flagged unreliable underestimate)')
    parser.add_argument('--check', metavar='DOC', help='fail unless DOC holds the table, row for row')
    parser.add_argument('runs', nargs='+', help='result.json of each box')
    args = parser.parse_args()
    if not (args.error_scale > 0 and math.isfinite(args.error_scale)):
        fail(f'--error-scale {args.error_scale}: must be a positive number')
    runs = sorted((load(name, args.quantity) for name in args.runs), key=lambda r: r['N'])
    if len({r['N'] for r in runs}) < 2:
        fail(f'{len(args.runs)} run(s) with N = {sorted({r["N"] for r in runs})}: need at least two box sizes')
    bad = [r['file'] for r in runs if not (r['error'] > 0)]
    if bad:
        fail(f'no positive error in {", ".join(bad)}: the fit weights each run by 1 / error^2')
    lines = table(runs, args.quantity, args.error_scale)
    if not args.check:
        print('\n'.join(lines))
        return
    doc = [line.rstrip() for line in open(args.check)]
    n = len(lines)
    if not any(doc[i:i + n] == lines for i in range(len(doc) - n + 1)):
        missing = [r for r in lines if r and r not in doc]
        fail(f'{args.check} does not hold this table as the runs give it:\n' + '\n'.join(lines) +
             ('\nmissing lines:\n' + '\n'.join(missing) if missing else ''))
    print(f'{args.check} holds the extrapolation of {", ".join(args.runs)}')


if __name__ == '__main__':
    main()
