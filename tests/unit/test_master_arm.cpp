// The master arm model (FK, Jacobians, gravity, torque mapping of eqs 8, 10, 25-27) and the
// simulated master arm device driven by a simulated operator (closed loop).
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <random>
#include <set>
#include <vector>

#include "alloc_counter.hpp"
#include "hapticgrasp/device/master_arm.hpp"
#include "hapticgrasp/device/simulated_operator.hpp"

using namespace hg;
using namespace hg::device;

namespace {

std::shared_ptr<const ArmModel> model() {
  static const std::shared_ptr<const ArmModel> m =
      ArmModel::fromFile(std::string(HG_RESOURCES_DIR) + "/arms/master_arm.urdf");
  return m;
}

ArmVector randomJoints(std::mt19937& rng) {
  const ArmModel& m = *model();
  ArmVector q;
  for (int j = 0; j < kArmJoints; ++j) {
    // Inside the limits, away from them.
    std::uniform_real_distribution<double> u(m.lowerLimits()[j] + 0.1, m.upperLimits()[j] - 0.1);
    q[j] = u(rng);
  }
  return q;
}

Mat3 rotY(double a) { return Eigen::AngleAxisd(a, Vec3::UnitY()).toRotationMatrix(); }

// Rotation vector of R (log map).
Vec3 rotationVector(const Mat3& r) {
  const Eigen::AngleAxisd aa(r);
  return aa.angle() * aa.axis();
}

void expectNear(const Vec3& a, const Vec3& b, double tol, const char* what) {
  EXPECT_LT((a - b).norm(), tol) << what << ": " << a.transpose() << " vs " << b.transpose();
}

}  // namespace

TEST(MasterArm, LoadsTheUrdf) {
  const ArmModel& m = *model();
  EXPECT_EQ(m.indexChain().getNrOfJoints(), 8u);
  EXPECT_EQ(m.thumbChain().getNrOfJoints(), 9u);
  EXPECT_EQ(m.wristChain().getNrOfJoints(), 7u);
  EXPECT_STREQ(ArmModel::jointNames()[kElbowFlexion], "elbow_flexion");
  EXPECT_DOUBLE_EQ(m.effortLimits()[kShoulderFlexion], 40);
  EXPECT_DOUBLE_EQ(m.effortLimits()[kIndexFlexion], 2);
  EXPECT_NEAR(m.totalMass(), 0.2 + 0.2 + 2.0 + 0.15 + 1.5 + 0.1 + 0.4 + 0.03 + 0.02 + 0.015, 1e-12);
  for (int j = 0; j < kArmJoints; ++j) EXPECT_LT(m.lowerLimits()[j], m.upperLimits()[j]);
  EXPECT_THROW(ArmModel::fromFile("/nonexistent/arm.urdf"), std::runtime_error);
  EXPECT_THROW(ArmModel::fromString("<robot name='x'><link name='base'/></robot>"), std::runtime_error);
}

// A joint whose child is its own parent: a clear error, and (fuzz_urdf, under
// LeakSanitizer) the parsed model no longer leaks through the loop it makes.
TEST(MasterArm, JointLoopIsRefused) {
  std::ifstream in(ArmModel::defaultUrdfPath());
  std::string urdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string joint = R"(<parent link="shoulder_yoke1"/><child link="shoulder_yoke2"/>)";
  const std::size_t at = urdf.find(joint);
  ASSERT_NE(at, std::string::npos);
  urdf.replace(at, joint.size(), R"(<parent link="shoulder_yoke2"/><child link="shoulder_yoke2"/>)");
  EXPECT_THROW(ArmModel::fromString(urdf), std::runtime_error);
}

// Text that is not UTF-8 is refused before urdfdom reads it: TinyXML 2.6 skips a character
// by its lead byte alone, so lead bytes at the end of the text (fuzz_urdf: a run of 0xF4)
// carried it past the terminating NUL and read beyond the buffer. Well-formed multi-byte
// text passes.
TEST(MasterArm, TextThatIsNotUtf8IsRefused) {
  std::ifstream in(ArmModel::defaultUrdfPath());
  const std::string urdf((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t end = urdf.rfind("</robot>");
  ASSERT_NE(end, std::string::npos);
  const auto with = [&](const std::string& bytes) { return urdf.substr(0, end) + bytes + urdf.substr(end); };
  EXPECT_NO_THROW(ArmModel::fromString(with("<!-- Gr\xC3\xB6\xC3\x9F""e \xE2\x86\x92 \xF0\x9D\x9C\x83 -->")));
  for (const std::string& bad : {std::string("\xF4\xF4\xF4"), std::string("\x80"), std::string("\xC0\xAF"),
                                 std::string("\xED\xA0\x80"), std::string("\xF4\x90\x80\x80"),
                                 std::string("\xE2\x82"), std::string(1, '\0')}) {
    SCOPED_TRACE(testing::PrintToString(bad));
    try {
      ArmModel::fromString(with(bad));
      ADD_FAILURE() << "accepted";
    } catch (const std::runtime_error& e) {
      EXPECT_EQ(std::string(e.what()), "master arm: URDF string is not UTF-8 text (byte " + std::to_string(end) + ")");
    }
  }
  const std::string found = std::string(HG_TEST_DATA_DIR) + "/../fuzz/corpus/urdf/crash_utf8_lead_bytes_at_end.urdf";
  EXPECT_THROW(ArmModel::fromFile(found), std::runtime_error);
}

TEST(MasterArm, ForwardKinematicsZeroPose) {
  MasterArm arm(model());
  ArmPose p;
  arm.forwardKinematics(ArmVector::Zero(), p);
  // Arm hanging down: shoulder -> elbow 0.30, -> wrist 0.27, -> knuckle 0.09, -> tip 0.08.
  // p.wrist is the grasp's wrist point x_w, the URDF's "hand_reference": 0.08 behind the back
  // of the hand (-y, the palm faces +y) and 0.10 down from the wrist centre (0, 0, -0.57).
  expectNear(p.wrist, Vec3(0, -0.08, -0.67), 1e-12, "wrist");
  expectNear(model()->wristCentreOffset(), Vec3(0, -0.08, -0.10), 1e-15, "hand_reference offset");
  expectNear(p.index, Vec3(0, 0, -0.74), 1e-12, "index");
  // Thumb base 0.03 in front of and 0.03 below the wrist, then 0.04 + 0.035 down.
  expectNear(p.thumb, Vec3(0.03, 0, -0.675), 1e-12, "thumb");
  EXPECT_LT((p.wristRotation - Mat3::Identity()).norm(), 1e-12);
}

TEST(MasterArm, ForwardKinematicsElbowAt90Degrees) {
  MasterArm arm(model());
  ArmVector q = ArmVector::Zero();
  q[kElbowFlexion] = M_PI / 2;  // forearm forward (+x), about -y
  ArmPose p;
  arm.forwardKinematics(q, p);
  expectNear(p.wrist, Vec3(0.37, -0.08, -0.30), 1e-12, "wrist");  // centre (0.27, 0, -0.30)
  expectNear(p.index, Vec3(0.44, 0, -0.30), 1e-12, "index");
  expectNear(p.thumb, Vec3(0.375, 0, -0.27), 1e-12, "thumb");
  EXPECT_LT((p.wristRotation - rotY(-M_PI / 2)).norm(), 1e-12);

  // Shoulder flexed 90 degrees too: upper arm forward, forearm up.
  q[kShoulderFlexion] = M_PI / 2;
  arm.forwardKinematics(q, p);
  expectNear(p.wrist, Vec3(0.30, -0.08, 0.37), 1e-12, "wrist");  // centre (0.30, 0, 0.27)
  expectNear(p.index, Vec3(0.30, 0, 0.44), 1e-12, "index");
  expectNear(p.thumb, Vec3(0.27, 0, 0.375), 1e-12, "thumb");
  EXPECT_LT((p.wristRotation - rotY(-M_PI)).norm(), 1e-12);

  // Index curled 90 degrees towards the palm (+y) from the zero pose.
  q.setZero();
  q[kIndexFlexion] = M_PI / 2;
  arm.forwardKinematics(q, p);
  expectNear(p.index, Vec3(0, 0.08, -0.66), 1e-12, "index curled");
}

TEST(MasterArm, JacobiansMatchFiniteDifferences) {
  MasterArm arm(model());
  std::mt19937 rng(7);
  const double h = 1e-6;
  for (int trial = 0; trial < 20; ++trial) {
    const ArmVector q = randomJoints(rng);
    ArmKinematics kin;
    arm.kinematics(q, kin);
    ArmPose p0;
    arm.forwardKinematics(q, p0);
    expectNear(kin.pose.index, p0.index, 1e-15, "pose");
    for (int j = 0; j < kArmJoints; ++j) {
      ArmVector qp = q, qm = q;
      qp[j] += h;
      qm[j] -= h;
      ArmPose pp, pm;
      arm.forwardKinematics(qp, pp);
      arm.forwardKinematics(qm, pm);
      const Vec3 di = (pp.index - pm.index) / (2 * h);
      const Vec3 dt = (pp.thumb - pm.thumb) / (2 * h);
      const Vec3 dw = (pp.wrist - pm.wrist) / (2 * h);
      const Vec3 omega = rotationVector(pp.wristRotation * pm.wristRotation.transpose()) / (2 * h);
      const double dg = ((pp.index - pp.thumb).norm() - (pm.index - pm.thumb).norm()) / (2 * h);
      EXPECT_LT((kin.index.col(j) - di).norm(), 1e-6) << "J_i col " << j;
      EXPECT_LT((kin.thumb.col(j) - dt).norm(), 1e-6) << "J_t col " << j;
      EXPECT_LT((kin.wrist.col(j).head<3>() - dw).norm(), 1e-6) << "J_w linear col " << j;
      EXPECT_LT((kin.wrist.col(j).tail<3>() - omega).norm(), 1e-6) << "J_w angular col " << j;
      EXPECT_NEAR(kin.grasp(j), dg, 1e-6) << "J_g col " << j;
      // The wrist centre c = x_w - R_w * offset (the operator's point).
      const Vec3 off = model()->wristCentreOffset();
      const Vec3 dc = ((pp.wrist - pp.wristRotation * off) - (pm.wrist - pm.wristRotation * off)) / (2 * h);
      EXPECT_LT((kin.wristCentre.col(j) - dc).norm(), 1e-6) << "J_c col " << j;
    }
    expectNear(kin.wristCentreOffset, p0.wristRotation * model()->wristCentreOffset(), 1e-15, "x_w - c");
    EXPECT_NEAR(kin.gripDistance, (p0.index - p0.thumb).norm(), 1e-15);
  }
  // The fingers move only their own tips; the thumb does not move the wrist.
  ArmKinematics kin;
  arm.kinematics(randomJoints(rng), kin);
  EXPECT_EQ(kin.index.col(kThumbFlexion).norm(), 0);
  EXPECT_EQ(kin.thumb.col(kIndexFlexion).norm(), 0);
  EXPECT_EQ(kin.wrist.rightCols<3>().norm(), 0);
}

// Gravity torques of the whole tree = gradient of the potential energy V = -sum m_k g.c_k
// over every link (computed independently here, each link counted once).
TEST(MasterArm, GravityIsTheGradientOfThePotentialEnergy) {
  const auto m = model();
  MasterArm arm(m);
  const auto potential = [&](const ArmVector& q) {
    std::set<std::string> seen;
    double v = 0;
    const KDL::Chain* chains[] = {&m->indexChain(), &m->thumbChain(), &m->wristChain()};
    const std::array<int, kArmJoints>* cols[] = {&m->indexColumns(), &m->thumbColumns(), &m->wristColumns()};
    for (int c = 0; c < 3; ++c) {
      const KDL::Chain& chain = *chains[c];
      KDL::JntArray jq(chain.getNrOfJoints());
      for (unsigned k = 0; k < chain.getNrOfJoints(); ++k) jq(k) = q[(*cols[c])[k]];
      KDL::ChainFkSolverPos_recursive fk(chain);
      for (unsigned s = 0; s < chain.getNrOfSegments(); ++s) {
        const KDL::Segment& seg = chain.getSegment(s);
        if (!seen.insert(seg.getName()).second) continue;
        KDL::Frame f;
        fk.JntToCart(jq, f, static_cast<int>(s) + 1);
        const KDL::Vector com = f * seg.getInertia().getCOG();
        v += seg.getInertia().getMass() * 9.81 * com.z();
      }
    }
    return v;
  };
  std::mt19937 rng(11);
  for (int trial = 0; trial < 10; ++trial) {
    const ArmVector q = randomJoints(rng);
    ArmVector tau_g;
    arm.gravityTorques(q, tau_g);
    for (int j = 0; j < kArmJoints; ++j) {
      ArmVector qp = q, qm = q;
      qp[j] += 1e-6;
      qm[j] -= 1e-6;
      EXPECT_NEAR(tau_g[j], (potential(qp) - potential(qm)) / 2e-6, 1e-6) << "joint " << j;
    }
  }
  // Arm straight forward: the shoulder holds about (2.0*0.15 + 0.15*0.3 + 1.5*0.42 + ...) g.
  ArmVector q = ArmVector::Zero();
  q[kShoulderFlexion] = M_PI / 2;
  ArmVector tau_g;
  arm.gravityTorques(q, tau_g);
  EXPECT_GT(tau_g[kShoulderFlexion], 10);
  EXPECT_LT(tau_g[kShoulderFlexion], 15);
}

TEST(MasterArm, MassMatrixIsSymmetricPositiveDefinite) {
  MasterArm arm(model());
  std::mt19937 rng(3);
  ArmMatrix mm;
  arm.massMatrix(randomJoints(rng), mm);
  EXPECT_LT((mm - mm.transpose()).norm(), 1e-12);
  const Eigen::SelfAdjointEigenSolver<ArmMatrix> eig(mm);
  EXPECT_GT(eig.eigenvalues().minCoeff(), 0);
}

// tau = J^T f is the map of virtual work: tau . dtheta = f . dx for every small dtheta.
TEST(MasterArm, TorqueMappingIsVirtualWork) {
  MasterArm arm(model());
  std::mt19937 rng(5);
  std::normal_distribution<double> n(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    const ArmVector q = randomJoints(rng);
    ArmVector dq;
    for (int j = 0; j < kArmJoints; ++j) dq[j] = 1e-6 * n(rng);
    ArmPose pp, pm;
    arm.forwardKinematics(q + dq, pp);
    arm.forwardKinematics(q - dq, pm);
    ArmVector tau_g;
    arm.gravityTorques(q, tau_g);

    // Contact states (eq 10, both fingers).
    const Vec3 fi(n(rng), n(rng), n(rng)), ft(n(rng), n(rng), n(rng));
    const ArmTorques c = arm.contactTorques(q, fi, ft);
    ASSERT_FALSE(c.saturated());
    const double workC = fi.dot(pp.index - pm.index) + ft.dot(pp.thumb - pm.thumb);
    EXPECT_NEAR((c.tau - tau_g).dot(2 * dq), workC, 1e-12 + 1e-6 * std::abs(workC));

    // Grasp states (eq 25): wrist force and moment, grip force along the finger distance.
    const Vec3 fw(n(rng), n(rng), n(rng)), mw(0.1 * n(rng), 0.1 * n(rng), 0.1 * n(rng));
    const double fg = n(rng);
    const ArmTorques g = arm.graspTorques(q, fw, mw, fg);
    ASSERT_FALSE(g.saturated());
    const double workG = fw.dot(pp.wrist - pm.wrist) +
                         mw.dot(rotationVector(pp.wristRotation * pm.wristRotation.transpose())) +
                         fg * ((pp.index - pp.thumb).norm() - (pm.index - pm.thumb).norm());
    EXPECT_NEAR((g.tau - tau_g).dot(2 * dq), workG, 1e-12 + 1e-6 * std::abs(workG));
  }
  // Free state (eq 8): no force, gravity compensation only.
  const ArmVector q = randomJoints(rng);
  ArmVector tau_g;
  arm.gravityTorques(q, tau_g);
  EXPECT_LT((arm.contactTorques(q, Vec3::Zero(), Vec3::Zero()).tau - tau_g).norm(), 1e-14);
}

TEST(MasterArm, SaturatesToTheEffortLimits) {
  MasterArm arm(model());
  const ArmModel& m = arm.model();
  ArmVector q = ArmVector::Zero();
  q[kElbowFlexion] = M_PI / 2;
  // 1 kN pushing the index tip down: the index joint and several arm joints clamp.
  const ArmTorques big = arm.contactTorques(q, Vec3(0, 300, -1000), Vec3::Zero());
  EXPECT_TRUE(big.saturated());
  for (int j = 0; j < kArmJoints; ++j) {
    EXPECT_LE(std::abs(big.tau[j]), m.effortLimits()[j] + 1e-12);
    const bool over = std::abs(big.unsaturated[j]) > m.effortLimits()[j];
    EXPECT_EQ(over, ((big.saturatedMask >> j) & 1u) != 0) << "joint " << j;
    if (over) EXPECT_DOUBLE_EQ(big.tau[j], std::copysign(m.effortLimits()[j], big.unsaturated[j]));
    else EXPECT_DOUBLE_EQ(big.tau[j], big.unsaturated[j]);
  }
  EXPECT_TRUE((big.saturatedMask >> kIndexFlexion) & 1u);
  EXPECT_TRUE((big.saturatedMask >> kElbowFlexion) & 1u);
  // A realistic force does not saturate; a NaN force gives zero torque, flagged.
  EXPECT_FALSE(arm.contactTorques(q, Vec3(0, 0, -5), Vec3(0, 0, 5)).saturated());
  const ArmTorques bad = arm.contactTorques(q, Vec3(NAN, 0, 0), Vec3::Zero());
  EXPECT_TRUE(bad.tau.allFinite());
  EXPECT_TRUE(bad.saturated());
}

TEST(MasterArm, PerTickCallsDoNotAllocate) {
  MasterArm arm(model());
  std::mt19937 rng(1);
  std::vector<ArmVector> qs;
  for (int i = 0; i < 8; ++i) qs.push_back(randomJoints(rng));
  ArmPose pose;
  ArmKinematics kin;
  ArmVector tau_g, c;
  ArmMatrix mm;
  double sink = 0;
  const long before = hg::test::allocations();
  for (const ArmVector& q : qs) {
    arm.forwardKinematics(q, pose);
    arm.kinematics(q, kin);
    arm.gravityTorques(q, tau_g);
    arm.massMatrix(q, mm);
    arm.coriolisTorques(q, q, c);
    sink += arm.contactTorques(q, Vec3(1, 2, 3), Vec3(-1, 0, 2)).tau.sum();
    sink += arm.graspTorques(q, Vec3(1, 2, 3), Vec3(0.1, 0, 0), 2).tau.sum();
    sink += arm.mapTorques(kin, tau_g, Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3::Zero(), Vec3::Zero(), 1).tau.sum();
  }
  EXPECT_EQ(hg::test::allocations() - before, 0);
  EXPECT_TRUE(std::isfinite(sink));

  // The device's servo calls and the simulation step.
  const Vec3 start = SimulatedMasterArm().pose().index;
  SimulatedMasterArm device({}, keyframePath({{0, {start, start, start}}, {1, {start, start, start}}}));
  DeviceSample sample;
  DeviceCommand command;
  command.f_index = Vec3(1, 0, 0);
  const long before2 = hg::test::allocations();
  for (int i = 0; i < 20; ++i) {
    device.read(sample);
    device.write(command);
    device.advance(0.0005);
  }
  EXPECT_EQ(hg::test::allocations() - before2, 0);
}

namespace {
ArmVector holdPose() {
  ArmVector q = ArmVector::Zero();
  q << 0.4, 0.3, 0.2, M_PI / 2, 0.3, 0.2, 0.1, 0.5, 0.4, 0.6;
  return q;
}
}  // namespace

// Only gravity and tau_g act (nobody holds the arm): it stays put; without tau_g it falls.
TEST(SimulatedMasterArm, GravityCompensationHoldsTheArm) {
  SimulatedArmOptions options;
  options.initialJoints = holdPose();
  SimulatedMasterArm device(options);
  DeviceSample sample;
  ASSERT_TRUE(device.read(sample));
  const Vec3 index0 = sample.hand.index;
  for (int i = 0; i < 2000; ++i) {  // 1 s at 2 kHz
    device.write(DeviceCommand{});
    device.advance(0.0005);
  }
  EXPECT_LT((device.joints() - holdPose()).cwiseAbs().maxCoeff(), 1e-9);
  ASSERT_TRUE(device.read(sample));
  EXPECT_LT((sample.hand.index - index0).norm(), 1e-9);
  EXPECT_NEAR(device.time(), 1.0, 1e-9);

  options.gravityCompensation = false;
  SimulatedMasterArm falling(options);
  for (int i = 0; i < 1000; ++i) {  // 0.5 s
    falling.write(DeviceCommand{});
    falling.advance(0.0005);
  }
  DeviceSample fell;
  falling.read(fell);
  EXPECT_LT(fell.hand.index.z(), index0.z() - 0.1) << "the uncompensated arm should drop";
  EXPECT_LT(falling.joints()[kElbowFlexion], holdPose()[kElbowFlexion] - 0.3);
  EXPECT_TRUE(falling.joints().allFinite());
}

// In GRASP and MANIPULATE the grasp's command carries the grip force twice over: as f_g
// (eq 24, for a device with a grip joint) and as +-f_g h1 on the fingertips (for devices
// without one). The arm has a grip Jacobian: it must display eq 25 -- J_g^T f_g once, not
// J_g^T f_g plus J_i^T f_g h1 - J_t^T f_g h1 (the same torques again: twice the grip force,
// which kicked the operator's fingers past d_h and released the held part). Contact states
// (f_g = 0) still map the fingertip forces (eq 10).
TEST(SimulatedMasterArm, GraspCommandDisplaysTheGripForceOnce) {
  SimulatedArmOptions options;
  options.initialJoints = holdPose();
  SimulatedMasterArm device(options);
  const ArmPose p = device.pose();
  const Vec3 h1 = (p.index - p.thumb).normalized();
  DeviceCommand grasp;
  grasp.f_grasp = 3;
  grasp.f_index = grasp.f_grasp * h1;
  grasp.f_thumb = -grasp.f_index;
  grasp.f_wrist = Vec3(0.5, -1, -4);
  grasp.m_wrist = Vec3(0.02, 0.1, 0);
  device.write(grasp);
  const ArmTorques expected = device.arm().graspTorques(device.joints(), grasp.f_wrist, grasp.m_wrist, grasp.f_grasp);
  ASSERT_FALSE(expected.saturated());
  EXPECT_LT((device.lastTorques().unsaturated - expected.unsaturated).cwiseAbs().maxCoeff(), 1e-12)
      << "finger torques " << device.lastTorques().unsaturated.tail<3>().transpose() << " vs eq 25 "
      << expected.unsaturated.tail<3>().transpose();

  DeviceCommand contact;
  contact.f_index = Vec3(0, -2, 1);
  contact.f_thumb = Vec3(0.5, 1, 0);
  device.write(contact);
  const ArmTorques eq10 = device.arm().contactTorques(device.joints(), contact.f_index, contact.f_thumb);
  EXPECT_LT((device.lastTorques().unsaturated - eq10.unsaturated).cwiseAbs().maxCoeff(), 1e-12);
}

// The bench's operator with 10x firmer fingers (B / inertia ~1e4 /s on a finger joint),
// nudged off its target: it settles at any sub-step up to 1 ms. With the damping
// integrated explicitly, steps above ~0.3 ms blew up (0.5 ms: joint speeds of 2600 rad/s,
// the index tip thrown 55 mm).
TEST(SimulatedMasterArm, FirmFingersAreStableAtLongSteps) {
  for (double h : {1e-3, 0.5e-3, 0.2e-3}) {
    SimulatedMasterArm probe;
    const ArmPose rest = probe.pose();
    OperatorGains gains;
    for (int j = kIndexFlexion; j <= kThumbFlexion; ++j) {
      gains.stiffness[j] *= 10;
      gains.damping[j] *= 10;
    }
    const HandTarget target{rest.index, rest.thumb, rest.wrist};
    SimulatedMasterArm arm(SimulatedArmOptions{}, [target](double) { return target; }, gains);
    ArmVector q0 = arm.joints();
    q0[kIndexFlexion] -= 0.01;
    q0[kThumbFlexion] += 0.01;
    q0[kElbowFlexion] += 0.01;
    arm.setJoints(q0);
    double maxSpeed = 0, maxDrift = 0;
    for (int i = 0; i < static_cast<int>(std::lround(1.0 / h)); ++i) {
      arm.write(DeviceCommand{});
      arm.advance(h);
      maxSpeed = std::max(maxSpeed, arm.jointVelocities().cwiseAbs().maxCoeff());
      maxDrift = std::max(maxDrift, (arm.pose().index - rest.index).norm());
    }
    EXPECT_LT(maxSpeed, 1.0) << "step " << h;
    EXPECT_LT(maxDrift, 0.006) << "step " << h;  // the nudge itself moves the index tip 4.4 mm
    EXPECT_LT((arm.pose().index - rest.index).norm(), 0.001) << "step " << h;
  }
}

TEST(SimulatedMasterArm, SpecAndSamples) {
  SimulatedMasterArm device;
  const DeviceSpec& s = device.spec();
  EXPECT_TRUE(s.forceOutput);
  EXPECT_DOUBLE_EQ(s.maxForce_N, 20);
  EXPECT_GT(s.maxStiffness_N_per_m, 0);
  EXPECT_GT(s.timeout_s, 0);
  DeviceSample sample;
  EXPECT_TRUE(device.read(sample));
  EXPECT_FALSE(device.read(sample)) << "nothing new before advance()";
  EXPECT_TRUE(sample.hand.finite());
  EXPECT_EQ(sample.jointCount, kArmJoints);
  EXPECT_TRUE(s.workspace.contains(sample.hand.index));
  EXPECT_TRUE(s.workspace.contains(sample.hand.thumb));
  EXPECT_TRUE(s.workspace.contains(sample.hand.wrist));
  device.advance(0.0005);
  EXPECT_TRUE(device.read(sample));
  // Orthonormal wrist rotation.
  EXPECT_LT((sample.hand.wristRotation * sample.hand.wristRotation.transpose() - Mat3::Identity()).norm(), 1e-12);
}

namespace {
struct WallRun {
  double finalPenetration = 0;  // m, at the end
  double maxPenetration = 0;
  double finalSpeed = 0;  // m/s of the index tip, at the end
  double maxJointSpeed = 0;
  double finalIndexX = 0;
  bool finite = true;
};

// The operator pushes the whole hand 6 cm forward (+x); a wall 1 cm ahead of the index tip
// pushes back on the index tip only, f = -k * penetration, through write().
WallRun pushIntoWall(double k, double dt = 0.0005, double duration = 2.5) {
  const Vec3 push(0.06, 0, 0);
  SimulatedMasterArm probe;
  const ArmPose start = probe.pose();
  const double wallX = start.index.x() + 0.01;
  SimulatedMasterArm device(
      {}, keyframePath({{0.0, {start.index, start.thumb, start.wrist}},
                        {0.2, {start.index, start.thumb, start.wrist}},
                        {1.0, {start.index + push, start.thumb + push, start.wrist + push}}}));
  WallRun run;
  DeviceSample sample;
  Vec3 previous = start.index;
  const int steps = static_cast<int>(duration / dt);
  for (int i = 0; i < steps; ++i) {
    device.read(sample);
    const double pen = sample.hand.index.x() - wallX;
    DeviceCommand command;
    if (pen > 0) command.f_index = Vec3(-k * pen, 0, 0);
    device.write(command);
    device.advance(dt);
    run.finite = run.finite && sample.hand.finite() && device.joints().allFinite();
    run.maxPenetration = std::max(run.maxPenetration, pen);
    run.maxJointSpeed = std::max(run.maxJointSpeed, device.jointVelocities().cwiseAbs().maxCoeff());
    run.finalPenetration = pen;
    run.finalSpeed = (sample.hand.index - previous).norm() / dt;
    run.finalIndexX = sample.hand.index.x();
    previous = sample.hand.index;
  }
  return run;
}
}  // namespace

TEST(SimulatedMasterArm, OperatorStopsAtAStiffWall) {
  // Without the wall the operator's hand gets well past where the wall would be.
  const WallRun free = pushIntoWall(0);
  ASSERT_TRUE(free.finite);
  EXPECT_GT(free.finalPenetration, 0.03);
  std::printf("no wall: the index tip ends %.1f mm past the wall's plane\n", 1e3 * free.finalPenetration);

  double previousPenetration = 1;
  for (const double k : {100.0, 300.0, 1000.0, 2000.0}) {
    const WallRun run = pushIntoWall(k);
    std::printf("k %6.0f N/m: final penetration %.2f mm (max %.2f), wall force %.2f N, tip speed %.2g m/s, max joint speed %.2f rad/s\n",
                k, 1e3 * run.finalPenetration, 1e3 * run.maxPenetration, k * run.finalPenetration,
                run.finalSpeed, run.maxJointSpeed);
    ASSERT_TRUE(run.finite) << "k " << k;
    EXPECT_LT(run.maxJointSpeed, 10) << "k " << k;
    EXPECT_LT(run.finalSpeed, 1e-3) << "k " << k << ": the tip must come to rest";
    EXPECT_GT(run.finalPenetration, 0) << "k " << k << ": the operator keeps pushing";
    // It stops at the wall: much less penetration than the free run's travel, shrinking as
    // the wall stiffens, and the wall holds several newtons of push.
    EXPECT_LT(run.finalPenetration, 0.5 * free.finalPenetration) << "k " << k;
    EXPECT_LT(run.finalPenetration, previousPenetration) << "k " << k;
    EXPECT_GT(k * run.finalPenetration, 1.0) << "k " << k;
    // The operator's push is bounded, so the wall holds it below the device's force limit.
    EXPECT_LT(k * run.finalPenetration, 20.0) << "k " << k;
    EXPECT_LT(run.maxPenetration, 1.1 * run.finalPenetration + 1e-3) << "k " << k << ": no big overshoot";
    previousPenetration = run.finalPenetration;
  }
}

// Median per-call costs; run with --gtest_also_run_disabled_tests.
TEST(MasterArm, DISABLED_Timing) {
  MasterArm arm(model());
  std::mt19937 rng(2);
  std::vector<ArmVector> qs;
  for (int i = 0; i < 64; ++i) qs.push_back(randomJoints(rng));
  ArmPose pose;
  ArmKinematics kin;
  ArmVector tau_g;
  double sink = 0;
  const auto median = [&](auto&& call) {
    std::vector<double> ns;
    for (int rep = 0; rep < 200; ++rep) {
      const auto t0 = std::chrono::steady_clock::now();
      for (int i = 0; i < 100; ++i) call(qs[(rep + i) % qs.size()]);
      const auto t1 = std::chrono::steady_clock::now();
      ns.push_back(std::chrono::duration<double, std::nano>(t1 - t0).count() / 100);
    }
    std::nth_element(ns.begin(), ns.begin() + ns.size() / 2, ns.end());
    return ns[ns.size() / 2];
  };
  const double fk = median([&](const ArmVector& q) { arm.forwardKinematics(q, pose); sink += pose.index.x(); });
  const double jac = median([&](const ArmVector& q) { arm.kinematics(q, kin); sink += kin.grasp(0); });
  const double grav = median([&](const ArmVector& q) { arm.gravityTorques(q, tau_g); sink += tau_g[0]; });
  const double full = median([&](const ArmVector& q) {
    sink += arm.contactTorques(q, Vec3(1, 2, 3), Vec3(0, 1, 0)).tau[0];
  });
  SimulatedMasterArm device;
  DeviceCommand command;
  const double write = median([&](const ArmVector&) { device.write(command); });
  const double step = median([&](const ArmVector&) { device.advance(1e-6); });
  std::printf("median per call: FK %.0f ns, FK + all Jacobians %.0f ns, gravity %.0f ns, "
              "full torque mapping %.0f ns, device write %.0f ns, simulation step %.0f ns (%g)\n",
              fk, jac, grav, full, write, step, sink);
}

// How far the wall stiffness can go at two servo rates; run with --gtest_also_run_disabled_tests.
TEST(SimulatedMasterArm, DISABLED_WallStiffnessSweep) {
  for (const double dt : {0.0005, 0.001})
    for (const double k : {2000.0, 5000.0, 10000.0, 20000.0, 50000.0}) {
      const WallRun run = pushIntoWall(k, dt);
      std::printf("dt %.1f ms k %6.0f N/m: final penetration %.2f mm (max %.2f), tip speed %.2g m/s, max joint speed %.2f rad/s%s\n",
                  1e3 * dt, k, 1e3 * run.finalPenetration, 1e3 * run.maxPenetration, run.finalSpeed,
                  run.maxJointSpeed, run.finite ? "" : " NOT FINITE");
    }
}


namespace {
// The operator squeezes a block held between the fingertips: the targets aim 15 mm (index)
// and 40 mm (thumb) inside its sides (as the benches do), the block's sides push back on the
// fingertips (k = 2000 N/m along the grip axis). Returns the largest turn of the wrist frame
// from its start (rad) over `seconds`.
double squeezeTurn(bool holdOrientation, double seconds = 2.0) {
  SimulatedMasterArm probe;
  const ArmPose rest = probe.pose();
  const Vec3 centre = 0.5 * (rest.index + rest.thumb);
  const Vec3 u = (rest.index - rest.thumb).normalized();
  const double half = 0.5 * (rest.index - rest.thumb).norm() - 0.01;  // sides 10 mm inside the tips
  OperatorGains gains;
  for (int j = kIndexFlexion; j <= kThumbFlexion; ++j) {
    gains.stiffness[j] *= 10;
    gains.damping[j] *= 10;
  }
  HandTarget squeeze{centre + (half - 0.015) * u, centre - (half - 0.040) * u, rest.wrist};
  squeeze.holdOrientation = holdOrientation;
  squeeze.wristRotation = rest.wristRotation;
  SimulatedMasterArm arm(SimulatedArmOptions{}, [squeeze](double) { return squeeze; }, gains);
  const double dt = 0.0005, k = 2000;
  double maxTurn = 0;
  DeviceSample s;
  for (int i = 0; i < static_cast<int>(seconds / dt); ++i) {
    arm.read(s);
    DeviceCommand c;
    const double penI = half - (s.hand.index - centre).dot(u), penT = half + (s.hand.thumb - centre).dot(u);
    if (penI < 0) c.f_index = -k * penI * u;  // pushed back outward (+u)
    if (penT < 0) c.f_thumb = k * penT * u;   // pushed back outward (-u)
    arm.write(c);
    arm.advance(dt);
    const Mat3 R = arm.pose().wristRotation;
    maxTurn = std::max(maxTurn, Eigen::AngleAxisd(R * rest.wristRotation.transpose()).angle());
  }
  return maxTurn;
}
}  // namespace

// A human keeps the hand's orientation while squeezing: with holdOrientation the operator's
// least squares has the wrist's angular rows too and the hand stays level; without them the
// orientation is a null space of the position task and the squeezing fingers turn the hand.
TEST(SimulatedMasterArm, OperatorHoldsTheWristOrientationWhileSqueezing) {
  const double held = squeezeTurn(true), free = squeezeTurn(false);
  std::printf("wrist turn while squeezing: %.1f deg held, %.1f deg free\n", held * 180 / M_PI, free * 180 / M_PI);
  EXPECT_LT(held, 3.0 * M_PI / 180);
  EXPECT_GT(free, 2 * held);
}

// keyframePath interpolates the orientation between two keys that hold one, and an operator
// holding the orientation allocates nothing per step either.
TEST(SimulatedMasterArm, KeyframesInterpolateTheWristOrientation) {
  const ArmPose rest = SimulatedMasterArm().pose();
  HandTarget a{rest.index, rest.thumb, rest.wrist}, b = a;
  a.holdOrientation = b.holdOrientation = true;
  a.wristRotation = rest.wristRotation;
  b.wristRotation = Eigen::AngleAxisd(0.4, Vec3::UnitZ()).toRotationMatrix() * rest.wristRotation;
  const HandPath path = keyframePath({{0, a}, {1, b}});
  const HandTarget mid = path(0.5);
  EXPECT_TRUE(mid.holdOrientation);
  EXPECT_NEAR(Eigen::AngleAxisd(mid.wristRotation * a.wristRotation.transpose()).angle(), 0.2, 1e-9);
  EXPECT_NEAR(Eigen::AngleAxisd(path(2).wristRotation * b.wristRotation.transpose()).angle(), 0, 1e-9);
  HandTarget c{rest.index, rest.thumb, rest.wrist};  // aggregate initialization: no orientation
  EXPECT_FALSE(c.holdOrientation);
  EXPECT_FALSE(keyframePath({{0, c}, {1, c}})(0.5).holdOrientation);

  SimulatedMasterArm device({}, path);
  DeviceSample sample;
  const long before = hg::test::allocations();
  for (int i = 0; i < 20; ++i) {
    device.read(sample);
    device.write(DeviceCommand{});
    device.advance(0.0005);
  }
  EXPECT_EQ(hg::test::allocations() - before, 0);
}
