#!/usr/bin/env python3
"""Control forcing as a scalar loop, with the mode that rang in the prototype.

One marker's slip e under the control law f <- f + G e + P (e - e_prev) (f a force
density over rho). The liquid at the marker responds to the force spread in a step
by s f (s ~ 0.5: a marker's interpolation of its own and its neighbours' spread force,
docs/experiments/marker_overlap_eigenvalue.py) and relaxes towards the outer flow at
the viscous rate d = nu k^2 of the kernel's scale (k = pi / 1.5 dx). The liquid inside
the sphere adds a weakly damped acoustic mode: a displacement y with
y'' + 2 zeta w y' + w^2 y = q f, w = pi c_s / a_g (the closed sphere's lowest sound
mode), zeta = nu w / c_s^2 (its viscous damping), that the marker reads too.

What the controller observes decides the loop:
  committed:  v = u* + s f / 2 after the step, the velocity the next collision sees
              with the force still applied (engine/immersed_boundary/control_forcing.hpp);
  prototype:  the velocity the previous collision used, one step older
              (docs/experiments/feedback-forcing.patch).

Prints the largest |eigenvalue| of the linear loop over a grid of gains (< 1: stable)
at a = 6 (a_g 5.6) and the paper's viscosities.
    python3 docs/experiments/control_forcing_model.py
"""
import numpy as np

cs = 1 / np.sqrt(3)


def loop_matrix(G, P, nu, ag=5.6, s=0.5, q=0.3, lagged=False):
    d = nu * (np.pi / 1.5) ** 2
    w = np.pi * cs / ag
    zeta = nu * w / cs ** 2
    # state: x (outer liquid at the marker), y, y' (inside mode), f (force), e_prev, and for
    # the lagged observation the previous (x, y)
    # one step: observe, update the force, then the liquid moves under it.
    n = 7
    A = np.zeros((n, n))
    X, Y, Yd, F, E, XO, YO = range(n)
    # observation, as a row over the state
    obs = np.zeros(n)
    if lagged:
        obs[XO] = 1.0; obs[YO] = 1.0; obs[F] = s / 2
    else:
        obs[X] = 1.0; obs[Y] = 1.0; obs[F] = s / 2
    e = -obs  # target 0
    # new force
    fnew = np.zeros(n); fnew[F] = 1.0
    fnew += G * e + P * (e - np.eye(n)[E])
    # liquid after the step with fnew
    A[X] = (1 - d) * np.eye(n)[X] + s * fnew
    # inside mode, semi-implicit Euler with dt = 1
    yd_new = (1 - 2 * zeta * w) * np.eye(n)[Yd] - w ** 2 * np.eye(n)[Y] + q * fnew
    A[Yd] = yd_new
    A[Y] = np.eye(n)[Y] + yd_new
    A[F] = fnew
    A[E] = e
    A[XO] = np.eye(n)[X]
    A[YO] = np.eye(n)[Y]
    return A


def growth(G, P, nu, lagged):
    return max(abs(np.linalg.eigvals(loop_matrix(G, P, nu, lagged=lagged))))


if __name__ == "__main__":
    gains = [(0.05, 0), (0.25, 0.5), (0.5, 0), (1, 0), (2, 0), (3, 0), (4, 0), (1, 1), (2, 1)]
    for lagged in (False, True):
        print("observing", "the previous collision's velocity (prototype)" if lagged
              else "u* + s f / 2 after the step (committed)")
        print("  %-10s" % "G, P" + "".join("  nu=%-7g" % nu for nu in (0.005, 0.01, 0.02, 0.1667)))
        for G, P in gains:
            print("  %-10s" % f"{G}, {P}" + "".join("  %-10.5f" % growth(G, P, nu, lagged)
                                                  for nu in (0.005, 0.01, 0.02, 0.1667)))
