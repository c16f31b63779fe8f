#pragma once
// The master arm's model: kinematics, Jacobians, gravity and the torque mapping of the first
// paper (eqs 8, 10-11, 25-27), on orocos KDL chains loaded from a URDF with kdl_parser.
//
// Model/data split. ArmModel is immutable once built (the URDF, the three KDL chains
// base->index_tip, base->thumb_tip, base->hand_reference (x_w, off the finger line; the
// wrist centre "wrist" is a fixed offset from it), joint limits); share it between threads.
// MasterArm is the per-thread working state: the KDL solvers (which keep scratch buffers)
// and preallocated JntArray/Jacobian/JntSpaceInertiaMatrix. Its per-tick calls allocate
// nothing and do not throw. A MasterArm keeps its model alive (shared_ptr).
//
// Joint vector theta (N = 10), in this order (also documented in master_arm.urdf):
//   0 shoulder_flexion  1 shoulder_abduction  2 shoulder_rotation  3 elbow_flexion
//   4 forearm_pronation 5 wrist_flexion       6 wrist_deviation
//   7 index_flexion     8 thumb_abduction     9 thumb_flexion
// Positions are in the URDF base frame (the shoulder centre, z up); a device places that
// frame in the absolute frame by a translation only, so forces and torques map unchanged.
//
// Gravity and the mass matrix over the whole tree. The three chains share the arm and the
// hand segments (joints 0-6 and the hand's inertia), so per-chain results are combined
// without double counting: for the arm joints, tree = index chain + thumb chain - wrist
// chain (the wrist chain holds exactly the shared segments: arm links and hand, then the
// massless fixed hand_reference); the index joint is taken from the index chain, the thumb
// joints from the thumb chain. This is exact
// because gravity torques, mass matrices and Coriolis torques are sums of per-body terms.
#include <array>
#include <cstdint>
#include <memory>
#include <string>

#include <Eigen/Core>
#include <kdl/chain.hpp>
#include <kdl/chaindynparam.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/chainjnttojacsolver.hpp>
#include <kdl/jacobian.hpp>
#include <kdl/jntarray.hpp>
#include <kdl/jntspaceinertiamatrix.hpp>

#include "hapticgrasp/math/types.hpp"

namespace hg::device {

inline constexpr int kArmJoints = 10;
inline constexpr int kArmOnlyJoints = 7;  // shoulder 3, elbow 1, wrist 3
enum ArmJoint : int {
  kShoulderFlexion = 0,
  kShoulderAbduction,
  kShoulderRotation,
  kElbowFlexion,
  kForearmPronation,
  kWristFlexion,
  kWristDeviation,
  kIndexFlexion,
  kThumbAbduction,
  kThumbFlexion,
};

using ArmVector = Eigen::Matrix<double, kArmJoints, 1>;
using ArmMatrix = Eigen::Matrix<double, kArmJoints, kArmJoints>;
using ArmJacobian3 = Eigen::Matrix<double, 3, kArmJoints>;
using ArmJacobian6 = Eigen::Matrix<double, 6, kArmJoints>;
using ArmJacobian1 = Eigen::Matrix<double, 1, kArmJoints>;

// Forward kinematics, base frame.
struct ArmPose {
  Vec3 index = Vec3::Zero();  // x_i, index fingertip
  Vec3 thumb = Vec3::Zero();  // x_t, thumb tip
  // x_w, the grasp's wrist point (eq 17): the URDF's "hand_reference" frame behind the back
  // of the hand, well off the index-thumb line (the wrist centre lies nearly on that line,
  // which made eq 17's h2 magnify the fingers' yaw ~5x). Hand orientation.
  Vec3 wrist = Vec3::Zero();
  Mat3 wristRotation = Mat3::Identity();  // wrist (hand) frame -> base
};

// The pose and all Jacobians at one joint vector, base frame.
struct ArmKinematics {
  ArmPose pose;
  ArmJacobian3 index = ArmJacobian3::Zero();  // J_i = d x_i / d theta (eq 11)
  ArmJacobian3 thumb = ArmJacobian3::Zero();  // J_t = d x_t / d theta
  // J_w (eq 26): rows 0-2 d x_w / d theta, rows 3-5 the wrist's angular velocity per unit
  // joint rate (so [f_w; m_w] with m_w about the wrist centre maps by J_w^T).
  ArmJacobian6 wrist = ArmJacobian6::Zero();
  // d c / d theta of the wrist centre c = x_w - R_w * ArmModel::wristCentreOffset() (the
  // URDF's "wrist" frame): the simulated operator holds the hand there, as a person does.
  ArmJacobian3 wristCentre = ArmJacobian3::Zero();
  Vec3 wristCentreOffset = Vec3::Zero();  // x_w - c, base frame
  // J_g (eq 27) = d|x_i - x_t| / d theta = u^T (J_i - J_t), u = (x_i - x_t)/|x_i - x_t|;
  // zero when the fingertips coincide (the derivative does not exist there).
  ArmJacobian1 grasp = ArmJacobian1::Zero();
  double gripDistance = 0;  // |x_i - x_t|
};

// Joint torques after saturation to the effort limits.
struct ArmTorques {
  ArmVector tau = ArmVector::Zero();          // commanded, each |tau_j| <= effort_j
  ArmVector unsaturated = ArmVector::Zero();  // before the clamp
  std::uint32_t saturatedMask = 0;            // bit j: joint j was clamped
  bool saturated() const { return saturatedMask != 0; }
};

class ArmModel {
 public:
  // Throws std::runtime_error when the URDF cannot be read or lacks a frame or joint.
  static std::shared_ptr<const ArmModel> fromFile(const std::string& urdfPath);
  static std::shared_ptr<const ArmModel> fromString(const std::string& urdfXml);
  // resources/arms/master_arm.urdf of the source tree.
  static std::string defaultUrdfPath();

  static const std::array<const char*, kArmJoints>& jointNames();

  const ArmVector& lowerLimits() const { return lower_; }
  const ArmVector& upperLimits() const { return upper_; }
  const ArmVector& effortLimits() const { return effort_; }    // N m
  const ArmVector& velocityLimits() const { return velocity_; }  // rad/s
  double totalMass() const { return totalMass_; }
  Vec3 gravity() const { return gravity_; }  // m/s^2, base frame
  // x_w ("hand_reference") minus the wrist centre ("wrist"), in the hand frame.
  Vec3 wristCentreOffset() const { return wristCentreOffset_; }

  const KDL::Chain& indexChain() const { return index_; }
  const KDL::Chain& thumbChain() const { return thumb_; }
  const KDL::Chain& wristChain() const { return wrist_; }
  // Column of each chain joint in theta.
  const std::array<int, kArmJoints>& indexColumns() const { return indexCols_; }
  const std::array<int, kArmJoints>& thumbColumns() const { return thumbCols_; }
  const std::array<int, kArmJoints>& wristColumns() const { return wristCols_; }

  ArmModel(const ArmModel&) = delete;
  ArmModel& operator=(const ArmModel&) = delete;

 private:
  ArmModel() = default;
  static std::shared_ptr<const ArmModel> build(const std::string& xml, const std::string& what);

  KDL::Chain index_, thumb_, wrist_;
  std::array<int, kArmJoints> indexCols_{}, thumbCols_{}, wristCols_{};
  ArmVector lower_, upper_, effort_, velocity_;
  double totalMass_ = 0;
  Vec3 gravity_{0, 0, -9.81};
  Vec3 wristCentreOffset_ = Vec3::Zero();
};

// Per-thread working state. Every call below allocates nothing and is noexcept.
class MasterArm {
 public:
  explicit MasterArm(std::shared_ptr<const ArmModel> model);
  MasterArm(const MasterArm&) = delete;
  MasterArm& operator=(const MasterArm&) = delete;

  const ArmModel& model() const { return *model_; }
  const std::shared_ptr<const ArmModel>& modelPtr() const { return model_; }

  // Index, thumb and wrist positions and the wrist rotation.
  void forwardKinematics(const ArmVector& theta, ArmPose& pose) noexcept;
  // The pose and J_i, J_t, J_w, J_g.
  void kinematics(const ArmVector& theta, ArmKinematics& out) noexcept;
  // tau_g (eq 8): the joint torques that hold the arm's own weight (whole tree).
  void gravityTorques(const ArmVector& theta, ArmVector& tau_g) noexcept;
  // Joint-space mass matrix of the whole tree (for the simulation).
  void massMatrix(const ArmVector& theta, ArmMatrix& m) noexcept;
  // Coriolis and centrifugal torques C(theta, thetaDot) thetaDot, whole tree.
  void coriolisTorques(const ArmVector& theta, const ArmVector& thetaDot, ArmVector& c) noexcept;

  // Contact states (eq 10 for each finger): tau = J_i^T f_i + J_t^T f_t + tau_g.
  ArmTorques contactTorques(const ArmVector& theta, const Vec3& f_index, const Vec3& f_thumb) noexcept;
  // Grasp states (eq 25): tau = J_w^T [f_w; m_w] + J_g^T f_g + tau_g. f_g > 0 pushes the
  // fingertips apart (it resists squeezing, eq 24).
  ArmTorques graspTorques(const ArmVector& theta, const Vec3& f_wrist, const Vec3& m_wrist,
                          double f_grasp) noexcept;
  // Both at once, from precomputed kinematics and tau_g; then the saturation to the effort
  // limits. The caller passes zero for the terms of the other state: a grasp's command also
  // carries its grip force as +-f_g h1 fingertip forces, which would add J_g^T f_g a second
  // time (SimulatedMasterArm::write leaves them out when f_g > 0).
  ArmTorques mapTorques(const ArmKinematics& kin, const ArmVector& tau_g, const Vec3& f_index,
                        const Vec3& f_thumb, const Vec3& f_wrist, const Vec3& m_wrist,
                        double f_grasp) const noexcept;
  // Clamps each joint to +-effort.
  ArmTorques saturate(const ArmVector& tau) const noexcept;

 private:
  struct ChainWork {
    ChainWork(const KDL::Chain& chain, const KDL::Vector& g);
    KDL::ChainFkSolverPos_recursive fk;
    KDL::ChainJntToJacSolver jac;
    KDL::ChainDynParam dyn;
    KDL::JntArray q, qd, out;
    KDL::Jacobian J;
    KDL::JntSpaceInertiaMatrix M;
    KDL::Frame frame;
  };
  void load(ChainWork& w, const std::array<int, kArmJoints>& cols, const ArmVector& theta) noexcept;
  void loadChains(const ArmVector& theta) noexcept;

  std::shared_ptr<const ArmModel> model_;
  ChainWork index_, thumb_, wrist_;
  ArmKinematics kin_;  // scratch for the convenience calls
};

}  // namespace hg::device
