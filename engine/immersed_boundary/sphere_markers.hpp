#pragma once
// Marker points on a sphere surface for the immersed boundary.
#include <Eigen/Core>
#include <vector>

namespace flocsim::immersed_boundary {

// Unit directions of n points spread evenly over the sphere: the spherical
// Fibonacci lattice (golden-angle spiral, Swinbank & Purser 2006). Every
// point covers the same area 4 pi / n to within a few per cent and there are
// no clusters at the poles, unlike latitude-longitude grids.
std::vector<Eigen::Vector3d> fibonacci_sphere(int n);

// Number of markers on a sphere of radius r so that the mean marker spacing
// sqrt(4 pi r^2 / n) is at most `spacing`.
int marker_count(double radius, double spacing);

// Volume each marker represents: a shell one lattice spacing thick around the
// surface, shared equally, (4 pi / 3)((r + 1/2)^3 - (r - 1/2)^3) / n
// = pi (12 r^2 + 1) / (3 n) (Uhlmann 2005).
double marker_volume(double radius, int n);

}  // namespace flocsim::immersed_boundary
