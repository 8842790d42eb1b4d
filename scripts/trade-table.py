#!/usr/bin/env python3
"""The tables of an accuracy trade (docs/corners.md): runs of one case
at two or more U_inf, the same seeds at each.

SOURCE is either a folder holding each run as U<U_inf>-seed<seed>/result.json, or a runs.csv
with one row per run (columns U_inf, seed, F, F_err, U_over_Uinf, U_over_Uinf_err, C_sph,
C_sph_err, n_a_mean, n_a_mean_err, Re_T, Re_T_err, max_liquid_speed_over_U_inf,
max_liquid_Mach, coupling_worst_window, mass_balance_rel, momentum_balance_rel, steps, wall_s).
A folder may also hold runs named U<U_inf>-<variant>-seed<seed> (say U0.07-papers-method-seed1):
runs at that U_inf that differ from the trade's in one named way (another coupling method, say).
Each variant is a group of its own, listed after the trade's runs and compared with the trade's
own runs at its U_inf, so that only the named way differs (a variant at a U_inf the trade has no
runs at is refused); a runs.csv holds the trade's own runs only.

First table, one row per run: F, U/U_inf, C_sph, <n_a>, Re_T with the batch-means error each run
gives, the largest liquid speed in U_inf and its Mach number, and the coupling monitor's worst
window.

Second table, one row per group (each U_inf of the trade, then each variant): the mean over its
seeds, whose error is the larger of the seeds' scatter (sample standard deviation over sqrt(seeds))
and the runs' combined batch errors (root of the sum of their squares over the number of seeds).
Then the reference (the trade's own runs at the largest U_inf, the preset's, unless --reference
names another) against each other U_inf of the trade, and each variant's U_inf against the variant: the relative difference a/b - 1, its error (the ratio's:
a/b times the two relative errors in quadrature), and in brackets |a/b - 1| in units of that error.
Below: the balances and each run's steps and wall time.

--check DOC fails unless DOC holds each table as one whole table, row for row (for a runs.csv,
whose per-run figures stay in the file, the second table only). The trades' tables in
docs/corners.md are what this prints; the test DocTradeTableMatchesItsRuns holds them so.

Usage: scripts/trade-table.py [--reference U_INF] [--check DOC] SOURCE"""
import argparse, csv, json, math, pathlib, re, statistics, sys

# (label, key in result.json's observables and in runs.csv, decimals in a run's row, in a mean's)
FIGURES = [('F', 'F', 2, 2), ('U/U_inf', 'U_over_Uinf', 3, 3), ('C_sph', 'C_sph', 2, 2),
           ('<n_a>', 'n_a_mean', 1, 1), ('Re_T', 'Re_T', 1, 2)]


def fail(message):
    sys.exit(f"trade-table.py: {message}")


def run_from_result(path, U_inf, seed):
    r = json.load(open(path))
    if r.get('status') != 'completed':
        fail(f"{path}: status {r.get('status')!r}: no table from a run that did not complete")
    try:
        if not math.isclose(r['derived']['U_inf'], U_inf, rel_tol=1e-9) or r['case']['seed'] != seed:
            fail(f"{path}: the run has U_inf {r['derived']['U_inf']:g} and seed {r['case']['seed']}, "
                 f"its folder says {U_inf:g} and {seed}")
        o, cost = r['observables'], r['cost']
        return {'figures': {key: (o[key]['mean'], o[key]['error']) for _, key, _, _ in FIGURES},
                'speed_over_U_inf': o['max_liquid_speed'] / U_inf, 'Mach': o['max_liquid_Mach'],
                'monitor': o['coupling_oscillation']['worst_window'],
                'mass': o['mass_balance']['relative_to_liquid_mass'],
                'momentum': o['momentum_balance']['relative_to_sphere_momentum'],
                'overlap': o['events']['worst_overlap'], 'steps': cost['steps'], 'wall_s': cost['wall_s']}
    except (KeyError, TypeError) as e:
        fail(f"{path}: not a flocsim result.json with every figure a trade needs ({type(e).__name__}: {e})")


def run_from_csv(row, where):
    def number(key):
        if key not in row:
            fail(f"{where}: no column {key}")
        try:
            return float(row[key])
        except (TypeError, ValueError):
            fail(f"{where}: column {key} is {row[key]!r}, not a number")
    return {'figures': {key: (number(key), number(key + '_err')) for _, key, _, _ in FIGURES},
            'speed_over_U_inf': number('max_liquid_speed_over_U_inf'), 'Mach': number('max_liquid_Mach'),
            'monitor': number('coupling_worst_window'), 'mass': number('mass_balance_rel'),
            'momentum': number('momentum_balance_rel'), 'overlap': None,
            'steps': int(number('steps')), 'wall_s': number('wall_s')}


def label(group):
    """A group of runs, (U_inf, variant), as the tables name it: 0.07, or 0.07 papers-method."""
    U_inf, variant = group
    return f"{U_inf:g}" + (f" {variant}" if variant else '')


def load(source):
    """{(U_inf, variant): {seed: run}}, every figure finite and the same seeds in every group; the
    variant is '' for the trade's own runs."""
    runs = {}

    def add(group, seed, run, where):
        if seed in runs.setdefault(group, {}):
            fail(f"{where}: a second run at U_inf {label(group)}, seed {seed}: which one the table means is not clear")
        runs[group][seed] = run

    path = pathlib.Path(source)
    if path.is_dir():
        for folder in sorted(path.glob('U*-seed*')):
            match = re.fullmatch(r'U([0-9.]+)(?:-([a-z][a-z0-9-]*))?-seed([0-9]+)', folder.name)
            if not match:
                fail(f"{folder}: not named U<U_inf>-seed<seed> or U<U_inf>-<variant>-seed<seed>; rename it "
                     f"or move it out of {source}")
            if not (folder / 'result.json').is_file():
                fail(f"{folder}: no result.json")
            U_inf, seed = float(match.group(1)), int(match.group(3))
            add((U_inf, match.group(2) or ''), seed, run_from_result(folder / 'result.json', U_inf, seed), folder)
    elif path.is_file():
        for line, row in enumerate(csv.DictReader(open(path)), start=2):
            where = f"{source}, line {line}"
            run = run_from_csv(row, where)
            try:
                U_inf, seed = float(row['U_inf']), int(row['seed'])
            except (KeyError, TypeError, ValueError):
                fail(f"{where}: U_inf {row.get('U_inf')!r} and seed {row.get('seed')!r} must be a number and an integer")
            add((U_inf, ''), seed, run, where)
    else:
        fail(f"{source}: neither a folder of runs nor a runs.csv")
    own = {U_inf for U_inf, variant in runs if not variant}
    if len(own) < 2:
        fail(f"{source}: a trade needs runs at two U_inf at least, found {sorted(label(g) for g in runs)}")
    for U_inf, variant in runs:
        if variant and U_inf not in own:
            fail(f"{source}: the variant {label((U_inf, variant))} has no runs of the trade's own at U_inf "
                 f"{U_inf:g} to be compared with (there are {sorted(label(g) for g in runs)})")
    seed_sets = {label(group): sorted(seeds) for group, seeds in runs.items()}
    if len(set(map(tuple, seed_sets.values()))) != 1:
        fail(f"{source}: the seeds differ between groups ({seed_sets}): the means would not compare")
    for group, seeds in runs.items():
        for seed, run in seeds.items():
            for key, (mean, error) in run['figures'].items():
                if not (math.isfinite(mean) and math.isfinite(error)):
                    fail(f"{source}: U_inf {label(group)} seed {seed}: {key} is {mean} +- {error}")
    # the trade's own runs, largest U_inf first, then the variants
    return dict(sorted(runs.items(), key=lambda item: (item[0][1] != '', -item[0][0], item[0][1])))


def mean_and_error(values, errors):
    n = len(values)
    combined = math.sqrt(sum(e * e for e in errors)) / n
    scatter = statistics.stdev(values) / math.sqrt(n) if n > 1 else 0.0
    return sum(values) / n, max(scatter, combined)


def short_exponent(value):
    """1.7e-5 rather than 1.7e-05; 0 as 0."""
    return '0' if value == 0 else f"{value:.1e}".replace('e-0', 'e-').replace('e+0', 'e+')


def difference_cell(a, error_a, b, error_b):
    """a against b in per cent, with the ratio's error, to that error's precision (one decimal below
    10 %), and the difference in errors."""
    if a == 0 or b == 0:
        return f"{a:g} against {b:g}"
    difference = a / b - 1
    error = (a / b) * math.hypot(error_a / a, error_b / b)
    digits = 0 if 100 * error >= 10 else 1
    text = f"{100 * difference:+.{digits}f} % +- {100 * error:.{digits}f} %"
    return text + (f" ({abs(difference) / error:.1f})" if error > 0 else " (exact)")


def per_run_table(runs):
    lines = ['| U_inf, seed | ' + ' | '.join(f[0] for f in FIGURES) +
             ' | largest liquid speed (U_inf); Mach | coupling monitor, worst window |',
             '|---' * (len(FIGURES) + 3) + '|']
    for group, seeds in runs.items():
        for seed, run in sorted(seeds.items()):
            cells = [f"{run['figures'][key][0]:.{digits}f} +- {run['figures'][key][1]:.{digits}f}"
                     for _, key, digits, _ in FIGURES]
            lines.append(f"| {label(group)}, {seed} | " + ' | '.join(cells) +
                         f" | {run['speed_over_U_inf']:.2f}; {run['Mach']:.3f} | {short_exponent(run['monitor'])} |")
    return lines


def means_table(runs, reference):
    means = {group: {key: mean_and_error([run['figures'][key][0] for run in seeds.values()],
                                         [run['figures'][key][1] for run in seeds.values()])
                     for _, key, _, _ in FIGURES}
             for group, seeds in runs.items()}
    lines = ['| | ' + ' | '.join(f[0] for f in FIGURES) + ' |', '|---' * (len(FIGURES) + 1) + '|']
    for group, m in means.items():
        lines.append(f"| U_inf {label(group)} | " +
                     ' | '.join(f"{m[key][0]:.{digits}f} +- {m[key][1]:.{digits}f}" for _, key, _, digits in FIGURES) +
                     ' |')
    for group in (g for g in means if g != reference):
        base = (group[0], '') if group[1] else reference  # a variant against its own U_inf
        cells = [difference_cell(*means[base][key], *means[group][key]) for _, key, _, _ in FIGURES]
        lines.append(f"| {label(base)} against {label(group)} | " + ' | '.join(cells) + ' |')
    return lines


def footer(runs):
    every = [(label(group), seed, run) for group, seeds in runs.items() for seed, run in sorted(seeds.items())]
    overlaps = [run['overlap'] for _, _, run in every if run['overlap'] is not None]
    return (f"over every run: mass to {max(run['mass'] for _, _, run in every):.1e} of the liquid's, momentum to "
            f"{max(run['momentum'] for _, _, run in every):.1e} of the spheres'" +
            (f", worst overlap {max(overlaps):g}" if overlaps else '') + "; steps and wall time: " +
            ', '.join(f"{name} seed {seed} {run['steps']} in {run['wall_s'] / 60:.1f} min" for name, seed, run in every))


def find_table(doc_lines, block):
    """Whether block stands in doc_lines as one whole table: its rows in order, no row before or after."""
    for i in range(len(doc_lines) - len(block) + 1):
        if doc_lines[i:i + len(block)] == block:
            before = doc_lines[i - 1] if i > 0 else ''
            after = doc_lines[i + len(block)] if i + len(block) < len(doc_lines) else ''
            if not before.startswith('|') and not after.startswith('|'):
                return True
    return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.split('\n\n')[0])
    parser.add_argument('--reference', type=float,
                        help="the U_inf whose own runs the others are compared with (default: the largest)")
    parser.add_argument('--check', metavar='DOC', help='fail unless DOC holds the tables, row for row')
    parser.add_argument('source', metavar='SOURCE')
    args = parser.parse_args()
    runs = load(args.source)
    plain = [U_inf for U_inf, variant in runs if not variant]  # two at least: load() refuses fewer
    reference = (max(plain) if args.reference is None else args.reference, '')
    if reference not in runs:
        fail(f"--reference {args.reference}: no runs of the trade's own at that U_inf "
             f"(there are {sorted(label(g) for g in runs)})")

    blocks = [means_table(runs, reference)]
    if pathlib.Path(args.source).is_dir():
        blocks.insert(0, per_run_table(runs))
    if args.check:
        doc_lines = [line.rstrip() for line in open(args.check)]
        for block in blocks:
            if not find_table(doc_lines, block):
                missing = [row for row in block if row not in doc_lines]
                fail(f"{args.check} does not hold this table of the trade in {args.source} as its runs give it" +
                     (f"; {args.check} lacks these rows, as the runs give them:\n" + '\n'.join(missing) if missing else
                      " as one whole table (every row is there, but not in order, or with other rows beside them):\n" +
                      '\n'.join(block)))
        print(f"{args.check} holds the tables of the trade in {args.source}")
        return
    print('\n\n'.join('\n'.join(block) for block in blocks))
    print('\n' + footer(runs))


if __name__ == '__main__':
    main()
