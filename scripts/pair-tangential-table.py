#!/usr/bin/env python3
"""The tables of a bonded pair sheared and rolled (docs/validation/bonded-pair.md), from the JSON files
bench_pair_tangential wrote (one per coupling scheme, each holding its slide and roll runs).

Per motion and component, each scheme's lattice share at every gap: the measured value less
what the box's periodic images and the scheme's own radius for rotation add, read at the
largest gap as measured minus exact and taken off at every gap (as the close-pair calibration
does for the normal approach), beside the exact pair's value, with the ratio in brackets.
Signs: the resisting components (the sliding force, the rolling torque) and the sliding torque
are given as magnitudes; the rolling force as it acts (+y, pushed by the neighbour).

--gaps S,... keeps only those gaps' rows (the offset is still read at the largest gap measured).
--check DOC fails unless DOC holds each table whole, row for row.

Usage: scripts/pair-tangential-table.py [--gaps S,...] [--check DOC] RUN.json [RUN.json ...]"""
import argparse
import json
import sys

# (motion, key in the JSON, its title, sign that makes the table's value)
COMPONENTS = [
    ('slide', 'force_y', 'sliding, force against the motion, -F_0y / (6 pi mu a V)', -1),
    ('slide', 'torque_z', 'sliding, torque from the gap, -T_0z / (8 pi mu a^2 V)', -1),
    ('roll', 'torque_z', 'rolling, torque against the rotation, -T_0z / (8 pi mu a^2 V)', -1),
    ('roll', 'force_y', 'rolling, force from the neighbour, F_0y / (6 pi mu a V)', +1),
]


def fail(message):
    print(f'pair-tangential-table.py: {message}', file=sys.stderr)
    sys.exit(1)


def scheme_label(text):
    """A short label for the scheme's description as bench_pair_tangential prints it."""
    if text.startswith('partially saturated'):
        return 'partially saturated cells'
    if '0.7 dx apart, 2 sweeps' in text:
        return "paper's method"
    if '1 dx apart, 1 sweep' in text:
        return 'one sweep'
    if 'control forcing' in text:
        return 'control forcing'
    return text


def tables(runs, shown=None):
    """Markdown lines of the four tables (rows at the gaps in `shown`, or all)."""
    out = []
    for motion, key, title, sign in COMPONENTS:
        chosen = [r for r in runs if r['motion'] == motion]
        if not chosen:
            continue
        gaps = [p['gap_over_a'] for p in chosen[0]['points']]
        for r in chosen:
            if [p['gap_over_a'] for p in r['points']] != gaps:
                fail(f'{r["scheme"]}, {motion}: other gaps than {gaps}')
        exact = [sign * p['exact_' + key] for p in chosen[0]['points']]
        out.append(f'{title}:')
        out.append('')
        out.append('| s/a | exact | ' + ' | '.join(scheme_label(r['scheme']) for r in chosen) + ' |')
        out.append('|---' * (2 + len(chosen)) + '|')
        shares = []
        for r in chosen:
            measured = [sign * p[key] for p in r['points']]
            offset = measured[-1] - exact[-1]
            shares.append(([m - offset for m in measured], offset))
        for k, gap in enumerate(gaps):
            if shown is not None and not any(abs(gap - g) < 1e-9 for g in shown):
                continue
            cells = [f'{v[k]:.3f} ({v[k] / exact[k]:.2f})' for v, _ in shares]
            out.append(f'| {gap:g} | {exact[k]:.3f} | ' + ' | '.join(cells) + ' |')
        out.append('| offset | | ' + ' | '.join(f'{off:+.4f}' for _, off in shares) + ' |')
        out.append('')
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n')[0])
    parser.add_argument('--check', metavar='DOC', help='fail unless DOC holds the tables, row for row')
    parser.add_argument('--gaps', help='only the rows at these gaps s/a, comma-separated')
    parser.add_argument('runs', nargs='+', help="bench_pair_tangential's --json files")
    args = parser.parse_args()
    shown = None
    if args.gaps:
        try:
            shown = [float(g) for g in args.gaps.split(',')]
        except ValueError:
            fail(f'--gaps {args.gaps}: not a comma-separated list of numbers')
    runs = []
    for name in args.runs:
        try:
            with open(name) as f:
                runs.extend(json.load(f)['runs'])
        except (OSError, ValueError, KeyError) as e:
            fail(f'{name}: not a bench_pair_tangential result ({e})')
    order = {"paper's method": 0, 'one sweep': 1, 'control forcing': 2, 'partially saturated cells': 3}
    runs.sort(key=lambda r: order.get(scheme_label(r['scheme']), 4))
    lines = tables(runs, shown)
    if not args.check:
        print('\n'.join(lines))
        return
    doc = [line.rstrip() for line in open(args.check)]
    blocks = '\n'.join(lines).split('\n\n')
    for block in blocks:
        rows = [r for r in block.split('\n') if r.startswith('|')]
        if not rows:
            continue
        n = len(rows)
        if not any(doc[i:i + n] == rows for i in range(len(doc) - n + 1)):
            missing = [r for r in rows if r not in doc]
            fail(f'{args.check} does not hold this table as the runs give it:\n' + '\n'.join(rows) +
                 ('\nmissing rows:\n' + '\n'.join(missing) if missing else ''))
    print(f'{args.check} holds the tables of {", ".join(args.runs)}')


if __name__ == '__main__':
    main()
