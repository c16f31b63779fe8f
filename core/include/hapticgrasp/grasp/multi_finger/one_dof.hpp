#pragma once
// The resultant-force paper's 1-DOF grasp (section 3 and 4): a part of length l between a
// thumb (the −x side) and an index finger (the +x side), both on the x axis.
//
//  - ConventionalOneDof: one coupled spring model per finger (eqs 4–6). The springs carry
//    both the grasping force and the resultant, so the gap is l − (2 f_g + |f_r|)/k (eq 8).
//  - ProposedOneDof: a mass-less shape shell balanced by the two grasping springs k_g
//    (section 4.1), a spring-damper k_d between the shell and the part's mass (section 4.2)
//    and the resultant given straight to one finger by eqs 10/11 (distributeOnLine, with
//    the erratum of DESIGN.md). The gap is l − 2 f_g / k_g (eq 12) whatever the resultant.
//
// Both integrate the part's motion with implicit (backward) Euler on the springs engaged
// at the start of the tick, so any stiffness and any dt in 1e-5..1e-1 s stay bounded.
// step() is allocation-free, lock-free and never throws: usable on the servo thread.
// Non-finite inputs are ignored (the last output is returned again).
namespace hg::grasp::multi_finger {

struct OneDofParams {
  double mass = 1.0;          // m [kg]
  double length = 0.06;       // l, the part's width along the grasp [m]
  double kGrasp = 800;        // k (conventional) / k_g (proposed) [N/m]
  double kDynamics = 800;     // k_d, shell–mass spring (proposed only) [N/m]
  double dampingRatio = 0.5;  // ζ of the contact dampers (conventional) and of the shell–mass damper
};

// One tick's answer. Forces along x, ON THE FINGERS (what the devices display).
struct OneDofOutput {
  double thumbForce = 0;     // [N], ≤ 0 while the thumb touches (pushed towards −x)
  double indexForce = 0;     // [N], ≥ 0 while the index touches
  double graspForce = 0;     // f_g of eq 2: the smaller of |thumbForce|, |indexForce| [N]
  double resultant = 0;      // f_r: the fingers' total force ON THE PART [N]
  double distance = 0;       // x_index − x_thumb [m]
  double partPosition = 0;   // x, the part's centre [m]
  double partVelocity = 0;   // [m/s]
  double shellPosition = 0;  // proposed: the shape shell's centre; conventional: = x [m]
  bool grasped = false;      // both fingers touch
};

class ConventionalOneDof {
 public:
  explicit ConventionalOneDof(const OneDofParams& params = {}) noexcept : p_(params) {}
  void reset(double partPosition, double partVelocity = 0) noexcept;
  // thumb, index: finger positions [m]; externalForce on the part along x [N]; dt [s].
  const OneDofOutput& step(double thumb, double index, double externalForce, double dt) noexcept;
  const OneDofOutput& output() const noexcept { return out_; }
  const OneDofParams& params() const noexcept { return p_; }

 private:
  OneDofParams p_;
  OneDofOutput out_;
  double x_ = 0, v_ = 0, lastThumb_ = 0, lastIndex_ = 0;
  bool haveLast_ = false;
};

class ProposedOneDof {
 public:
  explicit ProposedOneDof(const OneDofParams& params = {}) noexcept : p_(params) {}
  void reset(double partPosition, double partVelocity = 0) noexcept;
  const OneDofOutput& step(double thumb, double index, double externalForce, double dt) noexcept;
  const OneDofOutput& output() const noexcept { return out_; }
  const OneDofParams& params() const noexcept { return p_; }

 private:
  OneDofParams p_;
  OneDofOutput out_;
  double x_ = 0, v_ = 0, lastShell_ = 0;
  bool haveLast_ = false;
};

}  // namespace hg::grasp::multi_finger
