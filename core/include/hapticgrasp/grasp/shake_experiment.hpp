#pragma once
// The resultant-force paper's experiment (section 6, Fig. 8, Tables 1–2) in simulation: a
// rectangular block 6 cm wide and 10 cm high, gravity 2.0 m/s², springs 800 N/m, friction
// 1.0, grasped by thumb and index along its width (1 DOF, section 4). A simulated subject
// keeps its grip as the paper measured people do (section 2.4): its finger closure follows
// the grasping force it feels with a first-order response towards a target force (the
// weight's share over the friction, with a safety margin), while its wrist repeats eight
// horizontal shakes and two seconds of rest. Run for the conventional (eqs 4–8) and the
// proposed method (eqs 9–12). `hapticgrasp experiment shake [--json] [--plot FILE.svg]`.
#include <string>
#include <vector>

namespace hg::grasp {

struct ShakeConfig {
  double dt = 1e-3;               // servo period [s]
  double duration = 30;           // [s]; statistics over 0..duration
  double mass = 1.0;              // [kg] (section 2.3: 1 kg, 0.2 kgw at g = 2.0 m/s²)
  double width = 0.06;            // [m], along the grasp
  double height = 0.10;           // [m]
  double gravity = 2.0;           // [m/s²], vertical: held by friction
  double stiffness = 800;         // grasping springs (k, k_g) [N/m]
  double dynamicsStiffness = 800; // k_d [N/m]
  double dampingRatio = 0.5;      // of the contact / shell–mass dampers
  double friction = 1.0;          // μ
  double gripSafety = 2.0;        // target f_g = gripSafety · m g / (2 μ)
  double subjectTau = 0.2;        // [s], the subject's grip response time
  // The subject's finger compliance [N/m]: each finger gives way by force / handStiffness
  // with a first-order lag handTau (raised when needed for the lagged loop to be stable).
  // 0: a rigid, purely position-controlled hand.
  double handStiffness = 2000;
  double handTau = 0.02;          // [s], the lag of that give (the hand's mass and damping)
  double amplitude = 0.03;        // [m], A: the wrist moves A (1 − cos 2π f t) along the grasp
  double frequency = 1.5;         // [Hz]
  int shakes = 8;                 // shakes per sequence
  double rest = 2.0;              // [s] of rest after them
  double sampleRate = 100;        // [Hz] of the stored series (plot)
};

struct ShakeSeries {
  std::vector<double> t, graspForce, distance, resultant;
};

struct ShakeMethodResult {
  double grasp_force_mean_N = 0, grasp_force_std_N = 0;
  double distance_mean_m = 0, distance_std_m = 0;
  double resultant_max_N = 0;   // largest |f_r|
  double max_force_N = 0;       // largest force on a finger
  double slip_fraction = 0;     // share of ticks with 2 μ f_g < m g (the block would slip)
  bool finite = true;           // no NaN/inf anywhere
  ShakeSeries series;
};

struct ShakeResult {
  ShakeConfig config;
  double target_grasp_force_N = 0;
  ShakeMethodResult conventional, proposed;
};

// Deterministic; ~30 ms at the defaults. Throws std::invalid_argument for a non-positive
// dt, duration, mass, width or stiffness.
ShakeResult runShakeExperiment(const ShakeConfig& config = {});

// {"methods": {"conventional": {...}, "proposed": {...}}, "config": {...},
//  "target_grasp_force_N"}; each method: grasp_force_mean_N, grasp_force_std_N,
//  distance_mean_m, distance_std_m, resultant_max_N, max_force_N, slip_fraction.
std::string toJson(const ShakeResult& result, int indent = 2);

// Fig. 8: two panels (grasping force and finger distance against time), both methods.
std::string toSvg(const ShakeResult& result);

}  // namespace hg::grasp
