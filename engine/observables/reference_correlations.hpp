#pragma once
// Published correlations the settling observables are compared with
// (docs/model.md section 5). Written out once here so
// that result.json, the postprocess tool and the tests use the same formulas.
namespace flocsim::observables {

// Beetstra, van der Hoef & Kuipers (2007), the paper's eq. 4, with its Stokes
// part from van der Hoef et al. (2005). Normalisation: F = F_h / (6 pi mu a U)
// with F_h the force per sphere without the mean pressure gradient
// (= f V_p (1/phi - 1) for a body-force driven bed), U the superficial slip
// velocity, Re = U 2a / nu. Static random arrays, Re <= 1000, phi <= 0.6,
// about 10 % scatter.
double beetstra_drag(double phi, double reynolds);

// The settling velocity U/U_inf at which Beetstra's drag holds the spheres up:
// the force balance F_h = (1 - phi)(rho_p - rho) g V_p with U_inf from
// Schiller-Naumann gives F = (1 - phi)(1 + 0.15 Re_inf^0.687) U_inf / U, solved
// for U with F = beetstra_drag(phi, Re_inf U / U_inf). What a suspension whose
// spheres felt the drag of a static random array would settle at.
double beetstra_velocity_ratio(double phi, double reynolds_inf);

// Wylie, Koch & Ladd (2003) as the paper's eq. 5: the drag of spheres with
// random velocity fluctuations (granular temperature T, Re_T = T^(1/2) 2a/nu)
// on top of the mean slip, F(phi, Re, Re_T) = F(phi, Re, 0) + Re [0.0336 +
// 0.106 phi + 0.0116/(1 - phi)^5] x [(1 + 2 x^2 - x^4) erf(1/(sqrt 2 x)) +
// sqrt(2/pi) x (1 + x^2) exp(-1/(2 x^2))], x = Re_T / Re, with Beetstra's
// drag (eq. 4) as F(phi, Re, 0), as the paper uses it. At Re_T = 0 it is eq. 4.
double wylie_drag(double phi, double reynolds, double reynolds_t);

// Richardson & Zaki (1954) hindered settling, U / U_inf = (1 - phi)^n with
// n = 4.65 (Re < 0.2), 4.35 Re^-0.03 (0.2 <= Re < 1), 4.45 Re^-0.1
// (1 <= Re < 500), 2.39 (Re >= 500), Re the single-sphere Re_inf. Settling
// suspensions (not fixed beds), U the slip of the spheres through the liquid.
double richardson_zaki_exponent(double reynolds_inf);
double richardson_zaki_velocity_ratio(double phi, double reynolds_inf);

}  // namespace flocsim::observables
