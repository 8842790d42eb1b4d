#pragma once
// The exact creeping-flow resistance of two equal spheres to motions across
// their line of centres: the reference for a bonded pair sheared and rolled
// (docs/validation/bonded-pair.md).
//
// Jeffrey & Onishi (1984, J. Fluid Mech. 139, 261) write the force and torque
// on sphere 1 of a pair (unit vector d from sphere 1 to sphere 2, radius a)
// through scalar functions of the gap xi = s / a; for velocities U and
// angular velocities W normal to d,
//   F_1 = -6 pi mu a   [Y^A_11 U_1 + Y^A_12 U_2] + 4 pi mu a^2 [Y^B_11 W_1 - Y^B_12 W_2] x d
//   T_1 = -4 pi mu a^2 [Y^B_11 U_1 + Y^B_12 U_2] x d - 8 pi mu a^3 [Y^C_11 W_1 + Y^C_12 W_2]
// (equal spheres; their twin-multipole series in t = 2a / r). The series'
// coefficients come from their recurrences (eqs 4.6-4.11, 7.3-7.5), summed
// to order 100; the terms that make it converge slowly near contact, ln(1/xi)
// and xi ln(1/xi) with the coefficients of Jeffrey & Onishi as corrected by
// Townsend (2023, Phys. Fluids 35, 127126), are summed in closed form, so
// every gap xi > 0 converges (to about 1e-4: tests/lubrication).
//
// Two motions of the pair (sphere 0 at -x, sphere 1 at +x, as the held pair
// of engine/calibration/pair_resistance.hpp), each sphere's surface moving at
// V where it faces the other:
//   slide: U_0 = +V y, U_1 = -V y, no rotation; the surfaces slip past each
//          other at 2V, resisted as ln(1/xi) / 3 at contact;
//   roll:  no translation, W_0 = +V/a z, W_1 = -V/a z; the surfaces move
//          together, finite at contact.
namespace flocsim::lubrication {

struct TangentialFunctions {
  double YA11 = 0, YA12 = 0, YB11 = 0, YB12 = 0, YC11 = 0, YC12 = 0;
};

// The six functions at xi = s / a > 0.
TangentialFunctions equal_sphere_tangential_functions(double gap_over_a);

// slide: the force on sphere 0 against its motion, -F_0y / (6 pi mu a V)
// (-> 1 far apart), and its torque T_0z / (8 pi mu a^2 V) (< 0).
double sliding_pair_force(double gap_over_a);
double sliding_pair_torque(double gap_over_a);
// roll: the torque on sphere 0 against its rotation, -T_0z / (8 pi mu a^2 V)
// (-> 1 far apart), and its force F_0y / (6 pi mu a V) (> 0).
double rolling_pair_torque(double gap_over_a);
double rolling_pair_force(double gap_over_a);

}  // namespace flocsim::lubrication
