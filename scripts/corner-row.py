#!/usr/bin/env python3
"""One row of the grid's-corners table (docs/corners.md) from a corner
run's result.json: outcome and steps, largest liquid speed in lattice units and in U_inf, its Mach
number, largest sphere speed, worst overlap, mass and momentum balance, the coupling monitor's worst
window, U/U_inf, F and C_sph with their batch-means errors, and the wall time; on stderr the case's
numerics and what was not stationary.

Usage: scripts/corner-row.py RESULT.json [ESTIMATE]
  ESTIMATE   the wall time `sweep launch` (or `sweep plan`) printed for this point, e.g. "12.1 min",
             shown beside the measured one"""
import json, sys


def main(argv):
    if len(argv) not in (2, 3):
        sys.exit(__doc__)
    r = json.load(open(argv[1]))
    c, o, d, cost = r['case'], r['observables'], r['derived'], r['cost']
    U_inf = d['U_inf']

    def m(key, digits):
        v = o[key]
        return f"{v['mean']:.{digits}f} +- {v['error']:.{digits}f}"

    wall = cost['wall_s']
    wall_text = f"{wall / 60:.1f} min" if wall >= 120 else f"{wall:.1f} s"
    if len(argv) == 3:
        wall_text += f" ({argv[2]})"
    outcome = f"{r.get('status', 'completed')}, {cost['steps']} steps"
    if cost.get('steps_this_invocation', cost['steps']) != cost['steps']:
        outcome += f" ({cost['steps_this_invocation']} in the last invocation, which the extremes cover)"
    cells = 'x'.join(str(n) for n in d['box_cells'])
    print(f"| {c['phi']:g}, {c['Re_inf']:g}, {c['du_over_Uinf']:g} | {d['sphere_count']} | {outcome} | "
          f"{o['max_liquid_speed']:.3f} ({o['max_liquid_speed'] / U_inf:.2f}) | {o['max_liquid_Mach']:.2f} | "
          f"{o['max_sphere_speed']:.3f} ({o['max_sphere_speed'] / U_inf:.2f}) | "
          f"{o['events']['worst_overlap']:.2g} | "
          f"{o['mass_balance']['relative_to_liquid_mass']:.1e}; "
          f"{o['momentum_balance']['relative_to_sphere_momentum']:.1e} | "
          f"{o['coupling_oscillation']['worst_window']:.2g} | {m('U_over_Uinf', 3)} | {m('F', 2)} | "
          f"{o['C_sph']['mean']:.2f} | {wall_text} |")
    print(f"  ({cells} cells, nu {d['viscosity']:.4g}, tau {d['tau']:.4g}, U_inf {U_inf}, "
          f"{c['numerics'].get('immersed_boundary', 'preset IB')}, {c['precision']}, "
          f"{cost['threads']} threads, not stationary: {', '.join(r.get('not_stationary', [])) or 'none'})",
          file=sys.stderr)  # the row alone on stdout


if __name__ == '__main__':
    main(sys.argv)
