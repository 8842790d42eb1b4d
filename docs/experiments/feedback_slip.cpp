// One fixed sphere in a periodic cube under feedback forcing (needs feedback-forcing.patch):
// prints U, the sphere force over f L^3 and the rms/max marker slip over U.
// Usage: feedback_slip A_G NU L G P STEPS [U]   (build: see README.md here)
#include <cstdio>
#include <cstdlib>
#include <cmath>
#include "engine/calibration/hydrodynamic_radius.hpp"
#include "engine/lattice/fluid_lattice.hpp"
using namespace flocsim;
int main(int argc, char** argv) {
  double ag = atof(argv[1]); double nu = atof(argv[2]); int L = atoi(argv[3]);
  double G = atof(argv[4]), P = atof(argv[5]); int steps = atoi(argv[6]); double U = argc > 7 ? atof(argv[7]) : 1e-4;
  lattice::FluidLattice<double> fluid({L, L, L}, {nu, 0.25});
  immersed_boundary::ImmersedBoundarySettings st; st.input_radius = ag; st.forcing = immersed_boundary::Forcing::feedback;
  st.integral_gain = G; st.proportional_gain = P; st.measure_slip = true;
  immersed_boundary::ImmersedBoundary<double> ib(st);
  spheres::SphereSet sp; sp.radius = ag; sp.resize(1); sp.position[0] = spheres::Vec3::Constant(0.5 * L);
  double chi = 2*ag/L; double f = 6*M_PI*nu*ag*calibration::sangani_acrivos_drag(chi)*U/(double(L)*L*L);
  fluid.set_body_force({f,0,0});
  for (int n = 0; n < steps; ++n) {
    ib.apply(fluid, sp); fluid.step();
    if (n % (steps/40) == 0 || n < 10) { double u = fluid.total_momentum().x/fluid.total_mass();
      std::printf("%6d U %.6e F/fL3 %.5f rms slip/U %.3e max %.3e\n", n, u, -ib.force()[0].x()/(f*L*L*L), ib.rms_slip()/U, ib.max_slip()/U); }
    if (!std::isfinite(ib.rms_slip())) { std::printf("blew at %d\n", n); return 1; }
  }
}
