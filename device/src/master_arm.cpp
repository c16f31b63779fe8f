#include "hapticgrasp/device/master_arm.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string_view>

#include <kdl/tree.hpp>
#include <kdl_parser/kdl_parser.hpp>
#include <urdf_parser/urdf_parser.h>

#include "hapticgrasp/install_layout.hpp"


namespace hg::device {

namespace {

const std::array<const char*, kArmJoints> kJointNames = {
    "shoulder_flexion", "shoulder_abduction", "shoulder_rotation", "elbow_flexion",
    "forearm_pronation", "wrist_flexion", "wrist_deviation",
    "index_flexion", "thumb_abduction", "thumb_flexion"};

int jointIndex(const std::string& name) {
  for (int j = 0; j < kArmJoints; ++j)
    if (name == kJointNames[j]) return j;
  return -1;
}

// The offset of the first byte that is not part of well-formed UTF-8 (RFC 3629: no overlong
// forms, surrogates or code points past U+10FFFF), or npos. urdfdom's TinyXML 2.6 skips a
// multi-byte character by its lead byte alone: a lead byte near the end of the text carried
// it past the terminating NUL, reading beyond the buffer (found by fuzz_urdf). Written by
// hand: none of the project's libraries offers the check by itself.
std::size_t firstNonUtf8(std::string_view text) {
  std::size_t i = 0;
  while (i < text.size()) {
    const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
    const unsigned char lead = byte(i);
    int length = 0;
    unsigned char low = 0x80, high = 0xBF;  // the second byte's range
    if (lead == 0) return i;  // a NUL ends TinyXML's text early: not text either
    if (lead < 0x80) length = 1;
    else if (lead >= 0xC2 && lead <= 0xDF) length = 2;
    else if (lead >= 0xE0 && lead <= 0xEF) length = 3, low = lead == 0xE0 ? 0xA0 : 0x80, high = lead == 0xED ? 0x9F : 0xBF;
    else if (lead >= 0xF0 && lead <= 0xF4) length = 4, low = lead == 0xF0 ? 0x90 : 0x80, high = lead == 0xF4 ? 0x8F : 0xBF;
    else return i;
    if (i + length > text.size()) return i;
    for (int k = 1; k < length; ++k) {
      const unsigned char b = byte(i + k);
      if (b < (k == 1 ? low : 0x80) || b > (k == 1 ? high : 0xBF)) return i;
    }
    i += length;
  }
  return std::string_view::npos;
}

// Column of each movable chain joint in theta; -1 past the chain's joints.
std::array<int, kArmJoints> columnsOf(const KDL::Chain& chain, const std::string& tip) {
  std::array<int, kArmJoints> cols;
  cols.fill(-1);
  unsigned k = 0;
  for (const KDL::Segment& s : chain.segments) {
    if (s.getJoint().getType() == KDL::Joint::None) continue;
    const int j = jointIndex(s.getJoint().getName());
    if (j < 0 || k >= kArmJoints)
      throw std::runtime_error("master arm: chain to " + tip + " has an unknown joint '" +
                               s.getJoint().getName() + "'");
    cols[k++] = j;
  }
  return cols;
}

// urdfdom links each link to its children by shared_ptr. A joint whose child is its own
// parent (or any loop of joints) makes a cycle, and the parsed model, refused later by
// kdl_parser, was never freed (found by fuzz_urdf). The model is only read while the KDL
// tree is built, so its child lists are cleared when it goes, loop or not.
struct UrdfModelRelease {
  urdf::ModelInterfaceSharedPtr model;
  ~UrdfModelRelease() {
    if (!model) return;
    for (auto& [name, link] : model->links_)
      if (link) link->child_links.clear();
  }
};

}  // namespace

const std::array<const char*, kArmJoints>& ArmModel::jointNames() { return kJointNames; }

std::string ArmModel::defaultUrdfPath() {
  return (hg::resourcesDir() / "arms" / "master_arm.urdf").string();
}

std::shared_ptr<const ArmModel> ArmModel::fromFile(const std::string& urdfPath) {
  std::ifstream in(urdfPath);
  if (!in) throw std::runtime_error("master arm: cannot open " + urdfPath);
  std::ostringstream text;
  text << in.rdbuf();
  return build(text.str(), urdfPath);
}

std::shared_ptr<const ArmModel> ArmModel::fromString(const std::string& urdfXml) {
  return build(urdfXml, "URDF string");
}

std::shared_ptr<const ArmModel> ArmModel::build(const std::string& xml, const std::string& what) {
  if (const std::size_t bad = firstNonUtf8(xml); bad != std::string_view::npos)
    throw std::runtime_error("master arm: " + what + " is not UTF-8 text (byte " + std::to_string(bad) + ")");
  const urdf::ModelInterfaceSharedPtr urdfModel = urdf::parseURDF(xml);
  const UrdfModelRelease release{urdfModel};
  if (!urdfModel) throw std::runtime_error("master arm: " + what + " is not a valid URDF");
  KDL::Tree tree;
  if (!kdl_parser::treeFromUrdfModel(*urdfModel, tree))
    throw std::runtime_error("master arm: kdl_parser could not build a tree from " + what);

  std::shared_ptr<ArmModel> m(new ArmModel());
  const std::string root = tree.getRootSegment()->first;
  const auto chain = [&](const char* tip, KDL::Chain& out) {
    if (!tree.getChain(root, tip, out))
      throw std::runtime_error("master arm: " + what + " has no frame '" + tip + "'");
  };
  chain("index_tip", m->index_);
  chain("thumb_tip", m->thumb_);
  chain("hand_reference", m->wrist_);  // x_w: see the URDF
  m->indexCols_ = columnsOf(m->index_, "index_tip");
  m->thumbCols_ = columnsOf(m->thumb_, "thumb_tip");
  m->wristCols_ = columnsOf(m->wrist_, "hand_reference");
  {
    // Both frames hang off "hand" through fixed joints only.
    KDL::Chain toCentre, toReference;
    if (!tree.getChain("hand", "wrist", toCentre) || !tree.getChain("hand", "hand_reference", toReference))
      throw std::runtime_error("master arm: " + what + " has no 'hand', 'wrist' or 'hand_reference' frame");
    const auto pose = [&](const KDL::Chain& c) {
      if (c.getNrOfJoints() != 0)
        throw std::runtime_error("master arm: " + what + ": 'wrist' and 'hand_reference' must be fixed to 'hand'");
      KDL::Frame f = KDL::Frame::Identity();
      for (unsigned i = 0; i < c.getNrOfSegments(); ++i) f = f * c.getSegment(i).pose(0.0);
      return f;
    };
    const KDL::Frame rel = pose(toCentre).Inverse() * pose(toReference);
    m->wristCentreOffset_ = Vec3(rel.p.x(), rel.p.y(), rel.p.z());
  }
  // The combination of gravity and mass (see the header) needs the wrist chain to be the
  // arm joints 0-6 and the finger chains to extend it.
  for (int k = 0; k < kArmOnlyJoints; ++k)
    if (m->wristCols_[k] != k || m->indexCols_[k] != k || m->thumbCols_[k] != k)
      throw std::runtime_error("master arm: " + what + " does not have the arm joints 0-6 in order");
  if (m->wrist_.getNrOfJoints() != kArmOnlyJoints || m->index_.getNrOfJoints() != 8 ||
      m->thumb_.getNrOfJoints() != 9 || m->indexCols_[7] != kIndexFlexion ||
      m->thumbCols_[7] != kThumbAbduction || m->thumbCols_[8] != kThumbFlexion)
    throw std::runtime_error("master arm: " + what + " does not have the 7 + 1 + 2 joint layout");

  for (int j = 0; j < kArmJoints; ++j) {
    const urdf::JointConstSharedPtr joint = urdfModel->getJoint(kJointNames[j]);
    if (!joint || !joint->limits)
      throw std::runtime_error(std::string("master arm: joint '") + kJointNames[j] +
                               "' missing or without limits in " + what);
    m->lower_[j] = joint->limits->lower;
    m->upper_[j] = joint->limits->upper;
    m->effort_[j] = joint->limits->effort;
    m->velocity_[j] = joint->limits->velocity;
  }
  double mass = 0;
  for (const auto& [name, link] : urdfModel->links_)
    if (link->inertial) mass += link->inertial->mass;
  m->totalMass_ = mass;
  return m;
}

MasterArm::ChainWork::ChainWork(const KDL::Chain& chain, const KDL::Vector& g)
    : fk(chain),
      jac(chain),
      dyn(chain, g),
      q(chain.getNrOfJoints()),
      qd(chain.getNrOfJoints()),
      out(chain.getNrOfJoints()),
      J(chain.getNrOfJoints()),
      M(chain.getNrOfJoints()) {}

namespace {
KDL::Vector toKdl(const Vec3& v) { return KDL::Vector(v.x(), v.y(), v.z()); }
}  // namespace

MasterArm::MasterArm(std::shared_ptr<const ArmModel> model)
    : model_(std::move(model)),
      index_(model_->indexChain(), toKdl(model_->gravity())),
      thumb_(model_->thumbChain(), toKdl(model_->gravity())),
      wrist_(model_->wristChain(), toKdl(model_->gravity())) {}

void MasterArm::load(ChainWork& w, const std::array<int, kArmJoints>& cols,
                     const ArmVector& theta) noexcept {
  const unsigned n = w.q.rows();
  for (unsigned k = 0; k < n; ++k) w.q(k) = theta[cols[k]];
}

namespace {
Vec3 position(const KDL::Frame& f) { return {f.p.x(), f.p.y(), f.p.z()}; }
Mat3 rotation(const KDL::Frame& f) {
  Mat3 r;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) r(i, j) = f.M(i, j);
  return r;
}
}  // namespace

// The three chains share the arm's joints: each takes its columns of theta.
void MasterArm::loadChains(const ArmVector& theta) noexcept {
  load(index_, model_->indexColumns(), theta);
  load(thumb_, model_->thumbColumns(), theta);
  load(wrist_, model_->wristColumns(), theta);
}

void MasterArm::forwardKinematics(const ArmVector& theta, ArmPose& pose) noexcept {
  loadChains(theta);
  index_.fk.JntToCart(index_.q, index_.frame);
  thumb_.fk.JntToCart(thumb_.q, thumb_.frame);
  wrist_.fk.JntToCart(wrist_.q, wrist_.frame);
  pose.index = position(index_.frame);
  pose.thumb = position(thumb_.frame);
  pose.wrist = position(wrist_.frame);
  pose.wristRotation = rotation(wrist_.frame);
}

void MasterArm::kinematics(const ArmVector& theta, ArmKinematics& out) noexcept {
  forwardKinematics(theta, out.pose);  // also loads the chains' joint arrays
  index_.jac.JntToJac(index_.q, index_.J);
  thumb_.jac.JntToJac(thumb_.q, thumb_.J);
  wrist_.jac.JntToJac(wrist_.q, wrist_.J);
  out.index.setZero();
  out.thumb.setZero();
  out.wrist.setZero();
  // KDL's Jacobians: reference point at the chain tip, base-frame axes; rows vx vy vz wx wy wz.
  for (unsigned k = 0; k < index_.q.rows(); ++k)
    out.index.col(model_->indexColumns()[k]) = index_.J.data.block<3, 1>(0, k);
  for (unsigned k = 0; k < thumb_.q.rows(); ++k)
    out.thumb.col(model_->thumbColumns()[k]) = thumb_.J.data.block<3, 1>(0, k);
  for (unsigned k = 0; k < wrist_.q.rows(); ++k)
    out.wrist.col(model_->wristColumns()[k]) = wrist_.J.data.col(k);
  // Velocity of the wrist centre c = x_w - r: v_c = v_w - omega x r = v_w + [r]_x omega.
  const Vec3 r = out.pose.wristRotation * model_->wristCentreOffset();
  out.wristCentreOffset = r;
  Mat3 rx;
  rx << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  out.wristCentre.noalias() = out.wrist.topRows<3>() + rx * out.wrist.bottomRows<3>();
  const Vec3 d = out.pose.index - out.pose.thumb;
  out.gripDistance = d.norm();
  if (out.gripDistance > 1e-12)
    out.grasp.noalias() = (d / out.gripDistance).transpose() * (out.index - out.thumb);
  else
    out.grasp.setZero();
}

void MasterArm::gravityTorques(const ArmVector& theta, ArmVector& tau_g) noexcept {
  loadChains(theta);
  index_.dyn.JntToGravity(index_.q, index_.out);
  thumb_.dyn.JntToGravity(thumb_.q, thumb_.out);
  wrist_.dyn.JntToGravity(wrist_.q, wrist_.out);
  for (int k = 0; k < kArmOnlyJoints; ++k)
    tau_g[k] = index_.out(k) + thumb_.out(k) - wrist_.out(k);
  tau_g[kIndexFlexion] = index_.out(7);
  tau_g[kThumbAbduction] = thumb_.out(7);
  tau_g[kThumbFlexion] = thumb_.out(8);
}

void MasterArm::massMatrix(const ArmVector& theta, ArmMatrix& m) noexcept {
  loadChains(theta);
  index_.dyn.JntToMass(index_.q, index_.M);
  thumb_.dyn.JntToMass(thumb_.q, thumb_.M);
  wrist_.dyn.JntToMass(wrist_.q, wrist_.M);
  m.setZero();
  constexpr int a = kArmOnlyJoints;
  m.topLeftCorner<a, a>() = index_.M.data.topLeftCorner<a, a>() +
                            thumb_.M.data.topLeftCorner<a, a>() -
                            wrist_.M.data.topLeftCorner<a, a>();
  // Index: column 7 of the index chain; thumb: columns 7, 8 of the thumb chain.
  m.block<8, 1>(0, kIndexFlexion) = index_.M.data.block<8, 1>(0, 7);
  m.block<1, a>(kIndexFlexion, 0) = index_.M.data.block<1, a>(7, 0);
  m.block<a, 2>(0, kThumbAbduction) = thumb_.M.data.block<a, 2>(0, 7);
  m.block<2, a>(kThumbAbduction, 0) = thumb_.M.data.block<2, a>(7, 0);
  m.block<2, 2>(kThumbAbduction, kThumbAbduction) = thumb_.M.data.block<2, 2>(7, 7);
}

void MasterArm::coriolisTorques(const ArmVector& theta, const ArmVector& thetaDot,
                                ArmVector& c) noexcept {
  loadChains(theta);
  for (unsigned k = 0; k < index_.qd.rows(); ++k) index_.qd(k) = thetaDot[model_->indexColumns()[k]];
  for (unsigned k = 0; k < thumb_.qd.rows(); ++k) thumb_.qd(k) = thetaDot[model_->thumbColumns()[k]];
  for (unsigned k = 0; k < wrist_.qd.rows(); ++k) wrist_.qd(k) = thetaDot[model_->wristColumns()[k]];
  index_.dyn.JntToCoriolis(index_.q, index_.qd, index_.out);
  thumb_.dyn.JntToCoriolis(thumb_.q, thumb_.qd, thumb_.out);
  wrist_.dyn.JntToCoriolis(wrist_.q, wrist_.qd, wrist_.out);
  for (int k = 0; k < kArmOnlyJoints; ++k) c[k] = index_.out(k) + thumb_.out(k) - wrist_.out(k);
  c[kIndexFlexion] = index_.out(7);
  c[kThumbAbduction] = thumb_.out(7);
  c[kThumbFlexion] = thumb_.out(8);
}

ArmTorques MasterArm::saturate(const ArmVector& tau) const noexcept {
  ArmTorques r;
  r.unsaturated = tau;
  const ArmVector& limit = model_->effortLimits();
  for (int j = 0; j < kArmJoints; ++j) {
    double t = tau[j];
    if (!std::isfinite(t)) t = 0;  // never pass a NaN to a motor
    if (t > limit[j] || t < -limit[j] || t != tau[j]) r.saturatedMask |= 1u << j;
    r.tau[j] = std::clamp(t, -limit[j], limit[j]);
  }
  return r;
}

ArmTorques MasterArm::mapTorques(const ArmKinematics& kin, const ArmVector& tau_g,
                                 const Vec3& f_index, const Vec3& f_thumb, const Vec3& f_wrist,
                                 const Vec3& m_wrist, double f_grasp) const noexcept {
  Eigen::Matrix<double, 6, 1> wrench;
  wrench << f_wrist, m_wrist;
  ArmVector tau = tau_g;
  tau.noalias() += kin.index.transpose() * f_index;
  tau.noalias() += kin.thumb.transpose() * f_thumb;
  tau.noalias() += kin.wrist.transpose() * wrench;
  tau.noalias() += kin.grasp.transpose() * f_grasp;
  return saturate(tau);
}

ArmTorques MasterArm::contactTorques(const ArmVector& theta, const Vec3& f_index,
                                     const Vec3& f_thumb) noexcept {
  kinematics(theta, kin_);
  ArmVector tau_g;
  gravityTorques(theta, tau_g);
  return mapTorques(kin_, tau_g, f_index, f_thumb, Vec3::Zero(), Vec3::Zero(), 0);
}

ArmTorques MasterArm::graspTorques(const ArmVector& theta, const Vec3& f_wrist,
                                   const Vec3& m_wrist, double f_grasp) noexcept {
  kinematics(theta, kin_);
  ArmVector tau_g;
  gravityTorques(theta, tau_g);
  return mapTorques(kin_, tau_g, Vec3::Zero(), Vec3::Zero(), f_wrist, m_wrist, f_grasp);
}

}  // namespace hg::device
