#!/usr/bin/env python3
"""The two tables of an accuracy trade (docs/accuracy-cost.md, "The grid's corners"): runs of one
case at two or more U_inf, several seeds each, committed as FOLDER/U<U_inf>-seed<seed>/result.json.

First table, one row per run: F, U/U_inf, C_sph, <n_a>, Re_T with the batch-means error each
result.json gives, the largest liquid speed in U_inf and its Mach number, the coupling monitor's
worst window, and the steps and wall time.

Second table, one row per U_inf: the mean over its seeds; the error of the mean is the larger of
the seeds' scatter (sample standard deviation over sqrt(seeds)) and the runs' combined batch
errors (root of the sum of squares over the number of seeds). Then the first U_inf (the preset's,
the largest) against each other: the relative difference a/b - 1, its error (the ratio's: a/b
times the two relative errors in quadrature), and in brackets the difference in those errors.
The tables of the standard trade in docs/accuracy-cost.md are what this prints for its folder.

Usage: scripts/trade-table.py FOLDER
       scripts/trade-table.py --check DOC FOLDER   fails unless DOC holds every table row verbatim"""
import json, math, pathlib, re, statistics, sys

# (label, observables key, decimals in a run's row, decimals in a mean's row)
FIGURES = [('F', 'F', 2, 2), ('U/U_inf', 'U_over_Uinf', 3, 3), ('C_sph', 'C_sph', 2, 2),
           ('<n_a>', 'n_a_mean', 1, 1), ('Re_T', 'Re_T', 1, 2)]


def load(folder):
    runs = {}
    for path in sorted(pathlib.Path(folder).glob('U*-seed*/result.json')):
        match = re.fullmatch(r'U([0-9.]+)-seed([0-9]+)', path.parent.name)
        if not match:
            continue
        r = json.load(open(path))
        if r.get('status') != 'completed':
            sys.exit(f"{path}: status {r.get('status')!r}, not completed: no table from a run that did not finish")
        runs.setdefault(float(match.group(1)), {})[int(match.group(2))] = r
    if len(runs) < 2:
        sys.exit(f"{folder}: needs runs at two U_inf at least (found {sorted(runs)})")
    return dict(sorted(runs.items(), reverse=True))


def mean_and_error(values, errors):
    n = len(values)
    mean = sum(values) / n
    combined = math.sqrt(sum(e * e for e in errors)) / n
    scatter = statistics.stdev(values) / math.sqrt(n) if n > 1 else 0.0
    return mean, max(scatter, combined)


def short_exponent(value):
    """1.7e-5 rather than 1.7e-05; 0 as 0."""
    return '0' if value == 0 else f"{value:.1e}".replace('e-0', 'e-').replace('e+0', 'e+')


def percent(difference, error):
    """A difference and its error in per cent, to the error's precision: one decimal below 10 %."""
    digits = 0 if 100 * error >= 10 else 1
    return f"{100 * difference:+.{digits}f} % +- {100 * error:.{digits}f} % ({abs(difference) / error:.1f})"


def tables(runs):
    """The lines of both tables and the balances below them."""
    lines = ['| U_inf, seed | ' + ' | '.join(f[0] for f in FIGURES) +
             ' | largest liquid speed (U_inf); Mach | coupling monitor, worst window |',
             '|---' * (len(FIGURES) + 3) + '|']
    for U_inf, seeds in runs.items():
        for seed, r in sorted(seeds.items()):
            o = r['observables']
            cells = [f"{o[key]['mean']:.{digits}f} +- {o[key]['error']:.{digits}f}" for _, key, digits, _ in FIGURES]
            lines.append(f"| {U_inf:g}, {seed} | " + ' | '.join(cells) +
                         f" | {o['max_liquid_speed'] / U_inf:.2f}; {o['max_liquid_Mach']:.3f}"
                         f" | {short_exponent(o['coupling_oscillation']['worst_window'])} |")
    lines.append('')

    means = {}
    for U_inf, seeds in runs.items():
        means[U_inf] = {key: mean_and_error([r['observables'][key]['mean'] for r in seeds.values()],
                                            [r['observables'][key]['error'] for r in seeds.values()])
                        for _, key, _, _ in FIGURES}
    lines += ['| | ' + ' | '.join(f[0] for f in FIGURES) + ' |', '|---' * (len(FIGURES) + 1) + '|']
    for U_inf, m in means.items():
        lines.append(f"| U_inf {U_inf:g} | " +
                     ' | '.join(f"{m[key][0]:.{digits}f} +- {m[key][1]:.{digits}f}" for _, key, _, digits in FIGURES) +
                     ' |')
    first = next(iter(means))
    for U_inf in list(means)[1:]:
        cells = []
        for _, key, _, _ in FIGURES:
            (a, ea), (b, eb) = means[first][key], means[U_inf][key]
            cells.append(percent(a / b - 1, (a / b) * math.hypot(ea / a, eb / b)))  # the ratio's error
        lines.append(f"| {first:g} against {U_inf:g} | " + ' | '.join(cells) + ' |')

    every = [r for seeds in runs.values() for r in seeds.values()]
    lines.append('')
    lines.append(f"over every run: mass to {max(r['observables']['mass_balance']['relative_to_liquid_mass'] for r in every):.1e}"
                 f" of the liquid's, momentum to "
                 f"{max(r['observables']['momentum_balance']['relative_to_sphere_momentum'] for r in every):.1e} of the"
                 f" spheres', worst overlap {max(r['observables']['events']['worst_overlap'] for r in every):g}; steps and"
                 f" wall time: " + ', '.join(f"{r['case']['numerics']['U_inf'] if 'U_inf' in r['case']['numerics'] else r['derived']['U_inf']:g}"
                                             f" seed {r['case']['seed']} {r['cost']['steps']} in {r['cost']['wall_s'] / 60:.1f} min"
                                             for r in every))
    return lines


def main(argv):
    if len(argv) == 4 and argv[1] == '--check':
        doc_lines = set(line.rstrip() for line in open(argv[2]))
        missing = [line for line in tables(load(argv[3])) if line.startswith('|') and line not in doc_lines]
        if missing:
            sys.exit(f"{argv[2]} does not hold these rows of the trade in {argv[3]}, as its result.json files give them:\n" +
                     '\n'.join(missing))
        print(f"{argv[2]} holds every row of the trade in {argv[3]}")
        return
    if len(argv) != 2:
        sys.exit(__doc__)
    print('\n'.join(tables(load(argv[1]))))


if __name__ == '__main__':
    main(sys.argv)
