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

// The momentum and angular momentum of the liquid the lattice keeps inside
// each sphere, as measured step by step, and their change since the previous
// measurement: what the sphere equations add to the coupling's force and
// torque. Every coupling (on either device) keeps one.
class InsideMomenta {
 public:
  const std::vector<Vec3>& momentum() const { return momentum_; }
  const std::vector<Vec3>& angular_momentum() const { return angular_; }
  const std::vector<Vec3>& momentum_change() const { return momentum_change_; }
  const std::vector<Vec3>& angular_momentum_change() const { return angular_change_; }

  // Stores the momenta just measured and their change since the last ones
  // (zero at the first step, or for a sphere count that changed).
  void record(std::vector<Vec3> momentum, std::vector<Vec3> angular) {
    const std::size_t n = momentum.size();
    const bool have_previous = momentum_.size() == n;
    momentum_change_.assign(n, Vec3::Zero());
    angular_change_.assign(n, Vec3::Zero());
    if (have_previous)
      for (std::size_t s = 0; s < n; ++s) {
        momentum_change_[s] = momentum[s] - momentum_[s];
        angular_change_[s] = angular[s] - angular_[s];
      }
    momentum_ = std::move(momentum);
    angular_ = std::move(angular);
  }
  // A checkpoint's momenta, so that a resumed run continues identically.
  void restore(std::vector<Vec3> momentum, std::vector<Vec3> angular) {
    if (momentum.size() != angular.size())
      throw std::invalid_argument(
          "coupling: internal momenta need one entry per sphere in both lists");
    momentum_ = std::move(momentum);
    angular_ = std::move(angular);
  }

 private:
  std::vector<Vec3> momentum_, angular_;
  std::vector<Vec3> momentum_change_, angular_change_;
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
  const std::vector<Vec3>& internal_momentum_change() const { return inside_.momentum_change(); }
  const std::vector<Vec3>& internal_angular_momentum_change() const {
    return inside_.angular_momentum_change();
  }
  spheres::HydrodynamicLoads loads() const {
    return {force_, torque_, inside_.momentum_change(), inside_.angular_momentum_change()};
  }
  // The inside momenta measured in this step; with the setter, a checkpoint
  // restores them so that a resumed run continues identically.
  const std::vector<Vec3>& internal_momentum() const { return inside_.momentum(); }
  const std::vector<Vec3>& internal_angular_momentum() const { return inside_.angular_momentum(); }
  void set_internal_momenta(std::vector<Vec3> momentum, std::vector<Vec3> angular_momentum) {
    inside_.restore(std::move(momentum), std::move(angular_momentum));
  }

  // The scheme's own state for checkpoints (empty for schemes without one).
  virtual std::vector<NamedArray> memory() const { return {}; }
  virtual void restore_memory(const std::vector<NamedArray>& /*memory*/) {}

 protected:
  // Stores the inside momenta just measured and their change since the last
  // ones (zero at the first step, or for a sphere count that changed).
  void record_internal_momenta(std::vector<Vec3> momentum, std::vector<Vec3> angular) {
    inside_.record(std::move(momentum), std::move(angular));
  }

  std::vector<Vec3> force_, torque_;

 private:
  Scheme scheme_;
  InsideMomenta inside_;
};

}  // namespace flocsim::coupling
