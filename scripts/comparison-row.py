#!/usr/bin/env python3
"""One row of the comparison tables (docs/validation/comparison-points.md) from a run's result.json and, given, its du = 0 baseline's: U/U_inf, F, Re, Re_T, C_sph, <n_a> with their batch-means errors, the references, and F/F0 and <n_a>/<n_a>0 with the errors combined in quadrature.

Usage: scripts/comparison-row.py RESULT.json [BASELINE_RESULT.json]"""
import json, math, sys
r = json.load(open(sys.argv[1]))
o = r['observables']; c = r['case']
def m(k): return o[k]['mean'], o[k]['error']
U, dU = m('U_over_Uinf'); F, dF = m('F'); T, dT = m('Re_T'); C, dC = m('C_sph'); n, dn = m('n_a_mean')
ref = o['references']
row = f"| {c['phi']} | {c['Re_inf']} | {c['du_over_Uinf']} | {U:.3f} +- {dU:.3f} | {F:.3f} +- {dF:.3f} | {o['Re']['mean']:.2f} | {T:.2f} +- {dT:.2f} | {C:.3f} +- {dC:.3f} | {n:.2f} +- {dn:.2f} | {ref['beetstra_F_at_measured_Re']:.3f} | {ref['beetstra_U_over_Uinf']:.3f} | {ref['richardson_zaki_U_over_Uinf']:.3f} |"
print(row)
print('window', o['window'], 'steps', r['cost'].get('steps'), 'wall', r['cost'].get('wall_s'), 'stationary', {k: o[k]['stationary'] for k in ('F','U_over_Uinf','C_sph','n_a_mean')})
ev = o['events']; print('events', {k: ev[k] for k in ev if 'well' in k or 'escape' in k})
if len(sys.argv) > 2:
    b = json.load(open(sys.argv[2]))['observables']
    F0, dF0 = b['F']['mean'], b['F']['error']; n0, dn0 = b['n_a_mean']['mean'], b['n_a_mean']['error']
    ff = F / F0; dff = ff * math.hypot(dF / F, dF0 / F0)
    nn = n / n0; dnn = nn * math.hypot(dn / n, dn0 / n0)
    print(f"F/F0 = {ff:.3f} +- {dff:.3f}   <n_a>/<n_a>0 = {nn:.3f} +- {dnn:.3f}")
