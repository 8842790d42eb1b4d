#pragma once
// The one interface every coupling scheme offers the time loop (scheme.hpp
// lists them): impose no-slip on the spheres for one liquid step, and report
// what the liquid did to each sphere in that step.
//
// One step of a scene with spheres in a liquid (engine/run/coupled_step.hpp):
//
//   coupling.apply(liquid, spheres);       // forces / solid fractions for this step
//   liquid.step();                         // collision and streaming with them
//   coupling.after_liquid_step(liquid, spheres);
//   spheres::advance_velocities(spheres, coupling.loads(), ...);
//
// The loads are the hydrodynamic force and torque on each sphere (what the
// coupling took from the liquid to hold its surface, reversed) and the change
// of the momentum and angular momentum of the liquid the lattice keeps inside
// each sphere since the previous step; the sphere equations add that change
// (Kempe & Froehlich 2012), so that liquid and spheres together conserve
// momentum to round-off whatever the scheme (docs/model.md, section 1).
#include <stdexcept>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "engine/coupling/scheme.hpp"
#include "engine/lattice/forced_liquid.hpp"
#include "engine/spheres/sphere_dynamics.hpp"
#include "engine/spheres/sphere_set.hpp"

namespace flocsim::coupling {

using spheres::Vec3;

// State a scheme carries from step to step beyond the spheres' own (control
// forcing: the force of every marker), by name, for checkpoints.
struct NamedArray {
  std::string name;
  std::vector<double> values;
};

template <class Real>
class SphereCoupling {
 public:
  explicit SphereCoupling(const Scheme& scheme) : scheme_(scheme) {}
  virtual ~SphereCoupling() = default;
  SphereCoupling(const SphereCoupling&) = delete;
  SphereCoupling& operator=(const SphereCoupling&) = delete;

  const Scheme& scheme() const { return scheme_; }
  // The name its work is timed under (result.json, cost.modules_s).
  virtual std::string_view stage_name() const = 0;

  // Before the liquid's step: impose no-slip for the spheres where they are
  // and as they move now. Spheres must not move until after_liquid_step().
  virtual void apply(lattice::ForcedLiquid<Real>& liquid, const spheres::SphereSet& spheres) = 0;
  // After the liquid's step: completes this step's loads where the scheme
  // measures them during the step.
  virtual void after_liquid_step(const lattice::ForcedLiquid<Real>& /*liquid*/,
                                 const spheres::SphereSet& /*spheres*/) {}
  // Takes out of the liquid whatever apply() put in.
  virtual void remove(lattice::ForcedLiquid<Real>& liquid) = 0;

  // This step's loads, one entry per sphere.
  const std::vector<Vec3>& force() const { return force_; }
  const std::vector<Vec3>& torque() const { return torque_; }
  const std::vector<Vec3>& internal_momentum_change() const { return internal_momentum_change_; }
  const std::vector<Vec3>& internal_angular_momentum_change() const {
    return internal_angular_change_;
  }
  spheres::HydrodynamicLoads loads() const {
    return {force_, torque_, internal_momentum_change_, internal_angular_change_};
  }
  // The inside momenta measured in this step; with the setter, a checkpoint
  // restores them so that a resumed run continues identically.
  const std::vector<Vec3>& internal_momentum() const { return internal_momentum_; }
  const std::vector<Vec3>& internal_angular_momentum() const { return internal_angular_; }
  void set_internal_momenta(std::vector<Vec3> momentum, std::vector<Vec3> angular_momentum);

  // The scheme's own state for checkpoints (empty for schemes without one).
  virtual std::vector<NamedArray> memory() const { return {}; }
  virtual void restore_memory(const std::vector<NamedArray>& /*memory*/) {}

 protected:
  // Stores the inside momenta just measured and their change since the last
  // ones (zero at the first step, or for a sphere count that changed).
  void record_internal_momenta(std::vector<Vec3> momentum, std::vector<Vec3> angular);

  std::vector<Vec3> force_, torque_;

 private:
  Scheme scheme_;
  std::vector<Vec3> internal_momentum_, internal_angular_;
  std::vector<Vec3> internal_momentum_change_, internal_angular_change_;
};

template <class Real>
void SphereCoupling<Real>::set_internal_momenta(std::vector<Vec3> momentum,
                                                std::vector<Vec3> angular_momentum) {
  if (momentum.size() != angular_momentum.size())
    throw std::invalid_argument(
        "coupling: internal momenta need one entry per sphere in both lists");
  internal_momentum_ = std::move(momentum);
  internal_angular_ = std::move(angular_momentum);
}

template <class Real>
void SphereCoupling<Real>::record_internal_momenta(std::vector<Vec3> momentum,
                                                   std::vector<Vec3> angular) {
  const std::size_t n = momentum.size();
  const bool have_previous = internal_momentum_.size() == n;
  internal_momentum_change_.assign(n, Vec3::Zero());
  internal_angular_change_.assign(n, Vec3::Zero());
  if (have_previous)
    for (std::size_t s = 0; s < n; ++s) {
      internal_momentum_change_[s] = momentum[s] - internal_momentum_[s];
      internal_angular_change_[s] = angular[s] - internal_angular_[s];
    }
  internal_momentum_ = std::move(momentum);
  internal_angular_ = std::move(angular);
}

}  // namespace flocsim::coupling
