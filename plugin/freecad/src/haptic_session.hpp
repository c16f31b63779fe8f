#pragma once
// What the FreeCAD workbench drives: parts (BREP text in mm, placed by FreeCAD Placements),
// a device, and the real servo loop; snapshots come back in FreeCAD's units. No Python
// here: module.cpp binds it. Conversions go through freecad_boundary.hpp only.
#include <atomic>
#include <cstdint>
#include <memory>
#include <condition_variable>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "arm_input_device.hpp"
#include "freecad_boundary.hpp"
#include "hand_input_device.hpp"
#include "hid_input.hpp"
#include "hapticgrasp/geometry/mass_properties.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/geometry/penetration.hpp"
#include "hapticgrasp/grasp/grasp_parameters.hpp"
#include "hapticgrasp/scene/scene_build.hpp"
#include "hapticgrasp/servo/pose_tracker.hpp"
#include "hapticgrasp/servo/scripted_hand_device.hpp"
#include "hapticgrasp/servo/servo_loop.hpp"
#include "hapticgrasp/session/recorder.hpp"

namespace hg::freecad {

// A part's summary for the report view (mm, kg).
struct PartInfo {
  std::string name;
  int faces = 0;
  double volume_mm3 = 0;
  double mass_kg = 0;
  std::array<double, 3> centre_mm{0, 0, 0};
  std::string primitive;
  std::vector<std::string> warnings;
  std::array<double, 3> boundsMin_mm{0, 0, 0}, boundsMax_mm{0, 0, 0};  // object frame
  // The penetration back end that answers the part ("exact", "mesh", ...) and why, in one
  // line ("exact: valid B-rep", "mesh 0.01 mm: faces 27 and 31 cross (not healable); ...").
  std::string backend;
  std::string backendReason;
  double load_s = 0, check_s = 0;  // the part's load (BREP parsing included) and its checks
};

// Parses BREP text (mm, Placement reset) into a validated part; throws GeometryError.
// A set `cancelled` ends a load in the loader process at once.
geometry::PartModelPtr loadPart(const std::string& brep, const std::string& name,
                                const std::atomic<bool>* cancelled = nullptr);
// `penetration`: the back end that answers the part (its name goes in the summary).
PartInfo describe(const geometry::PartModel& part, const geometry::MassSpec& mass,
                  const geometry::PenetrationModel& penetration);

struct PartRequest;
struct BuiltPart;
// Loads, validates and models one part (slow: OpenCASCADE checks and the penetration
// back end); throws GeometryError / std::invalid_argument.
BuiltPart buildPart(const PartRequest& request, const std::atomic<bool>* cancelled = nullptr);

// One part to build: BREP text (mm, Placement reset), where it stands, its mass.
struct PartRequest {
  std::string name;
  std::string brep;
  Placement placement;
  geometry::MassSpec mass;
};

// A part built and ready for the servo loop: validated model, penetration back end, mass.
struct BuiltPart {
  grasp::ScenePart part;
  PartInfo info;
};

// Builds part models on its own worker thread (std::thread), one part after the other, so
// the caller (the GUI thread) never waits for OpenCASCADE: it polls progress() from its
// timer. A part that fails (GeometryError, a bad placement...) is recorded with its
// message and the build goes on with the others. cancel() stops it after the part in
// progress (a single part's load is not interruptible). Never touched by the servo thread.
class ModelBuild {
 public:
  struct Progress {
    std::size_t done = 0, total = 0;  // parts finished (built or failed), parts requested
    std::string current;              // the part being built ("" when none)
    bool finished = false;            // the worker is done (all parts, or cancelled)
    bool cancelled = false;
  };
  struct Outcome {
    std::size_t request = 0;          // index into the requests
    std::string name;
    std::optional<BuiltPart> built;   // empty: failed (error) or taken
    std::string error;
  };

  // Starts building `requests` at once. open: more may come with add() until close() (the
  // GUI hands parts over a few per timer tick); the build finishes only once closed.
  explicit ModelBuild(std::vector<PartRequest> requests, bool open = false);
  ~ModelBuild();  // cancels and joins
  // An open build: one more part (throws std::logic_error once closed or cancelled).
  void add(PartRequest request);
  void close();
  ModelBuild(const ModelBuild&) = delete;
  ModelBuild& operator=(const ModelBuild&) = delete;

  Progress progress() const;
  void cancel() noexcept;
  // Blocks until the worker is done, at most timeout_s (< 0: no limit); true when done.
  bool wait(double timeout_s = -1);
  // The outcomes so far, in request order (errors included); built parts not yet taken.
  std::vector<Outcome> outcomes() const;
  // Moves the built part of outcome `i` out (throws std::logic_error if none / not done).
  BuiltPart take(std::size_t i);

 private:
  void run() noexcept;

  std::vector<PartRequest> requests_;  // under mutex_ (add() appends)
  bool closed_ = true;
  mutable std::mutex mutex_;
  std::condition_variable done_, more_;
  Progress progress_;
  std::vector<Outcome> outcomes_;
  std::atomic<bool> cancel_{false};
  std::thread worker_;
};

// One part of a scene started at once (Session::startScene): its box from the shape
// (object frame, mm: FreeCAD's BoundBox of the shape without its Placement), where it
// stands, its mass, and the key its shape shares with identical ones (an App::Link's
// target, the same TShape); the shape's BREP text comes later (provideShape).
struct SceneRequest {
  std::string name;
  std::string key;
  std::array<double, 3> boxMin_mm{}, boxMax_mm{};
  Placement placement;
  geometry::MassSpec mass;
};

struct SceneStatus {
  std::size_t parts = 0, models = 0;  // parts, distinct shapes
  std::size_t built = 0, failed = 0;  // models
  std::size_t exactParts = 0;         // parts answered by their own model (the rest: their box)
  bool finished = false;
};

struct SessionSnapshot {
  std::uint64_t tick = 0;
  double time_s = 0;
  std::string state = "FREE";
  int graspedPart = -1;
  std::uint32_t events = 0;            // OR of the events since the previous snapshot()
  std::vector<std::string> eventNames;
  bool eventsLost = false;
  std::string fault = "none";          // active watchdog fault
  std::uint64_t faults = 0;            // watchdog trips since start
  std::vector<Placement> placements;   // every part, mm + quaternion
  // What the operator feels (after passivity, saturation and the watchdog's gain), N,
  // absolute frame (FreeCAD's axes): index and thumb fingertip forces, the grasping force.
  std::array<std::array<double, 3>, 2> forces_N{};
  double graspForce_N = 0;
  // The hand the servo loop last used, mm.
  std::array<double, 3> index_mm{0, 0, 0}, thumb_mm{0, 0, 0}, wrist_mm{0, 0, 0};
  // Every fingertip the method uses (the multi-finger method with a glove: up to five),
  // mm, and the force each feels, N.
  std::vector<std::array<double, 3>> fingertips_mm, fingertipForces_N;
  std::string method = "two-finger";
  double rate_hz = 0;      // achieved servo rate
  double jitter_us = 0;    // period error, p99
  // Every part's penetration back end and why (PartInfo::backend, backendReason), in part
  // order: what answers the fingertips, next to where they are.
  std::vector<std::pair<std::string, std::string>> backends;
  std::size_t exactParts = 0;  // parts answered by their own model (scene mode: the rest by their box)
  // Part-to-part contact of the carried part (contact/contact_report.hpp), FreeCAD's units.
  struct Contact {
    bool carried = false;                 // a part is carried with contact
    int part = -1, otherPart = -1;        // the carried part, and the nearest other one
    double clearance_mm = 0;              // to it; < 0: interference, by that depth
    bool exact = false;                   // false: no part within range (clearance is a lower bound)
    int heldFace = 0, otherFace = 0;      // 1-based, FreeCAD's FaceN; 0: an edge or vertex
    std::array<double, 3> heldPoint_mm{}, otherPoint_mm{};
    double penetration_mm = 0;            // deepest this tick
    double contactForce_N = 0;            // |what the other parts do to it|
    int active = 0;                       // contacts pushing
    bool lagging = false, saturated = false;
    int unmodelled = 0;                   // parts carried without a contact shell (they pass through)
    int letThrough = 0;                   // parts it interfered with where lifted (it passes through them)
  } contact;
};

// How the servo thread runs: what it asked for and got, and its timing so far (refreshed
// every 64 ticks). The workbench's panel and its GUI tests read it.
struct ServoTiming {
  double target_hz = 0, achieved_hz = 0;
  double periodErrP50_us = 0, periodErrP99_us = 0, periodErrMax_us = 0;
  std::uint64_t ticks = 0;
  std::string scheduler = "not started", memoryLock = "not started";  // ServoLoop's own words
  bool realtime = false;  // SCHED_FIFO granted
  std::string advice;     // why not, and how a user gets it; "" when granted or not asked for
};

// The session's recording (Session::recordTo), over every file it wrote: restart() closes
// the file and goes on in "<name>-2.mcap" beside it (see Session::restart).
struct RecordingStatus {
  std::string path;                 // the file being written (or the last one)
  std::vector<std::string> files;   // every file, in order
  bool recording = false;           // the current file's writer runs without error
  std::string error;                // why recording stopped or could not start; "" if it did not
  std::uint64_t ticks = 0, dropped = 0, bytes = 0, annotations = 0;  // summed over the files
  double duration_s = 0;            // summed over the files
};

class Session {
 public:
  Session() = default;
  ~Session();

  // Before start(). Returns the part's index. Throws GeometryError / std::invalid_argument.
  int addPart(const std::string& name, const std::string& brep, const Placement& placement,
              const geometry::MassSpec& mass);
  // Before start(): every part `build` built, in request order; returns their indices
  // (the failed requests get none: see build.outcomes()). Throws std::logic_error if the
  // build is not finished or was cancelled (a cancelled build adds nothing).
  std::vector<std::pair<std::size_t, int>> addBuilt(ModelBuild& build);
  // Any time (GUI thread): part `index` gets the one part `build` built (a rebuild after an
  // edit). A running servo loop keeps its scene until restart().
  void replacePart(std::size_t index, ModelBuild& build);
  // While running: stops the servo loop and starts a new one with the current parts,
  // standing at `placements` (mm, every part), with the same device and parameters. The
  // grasp starts again from FREE; snapshot time and ticks carry on.
  void restart(const std::vector<Placement>& placements);
  std::size_t partCount() const { return build_ ? sceneRequests_.size() : parts_.size(); }
  const PartInfo& partInfo(std::size_t i) const { return infos_.at(i); }

  // The device: a scripted hand (keys in mm, `frame` places the script's frame; key turns
  // are about the vertical through pivot_mm, absolute frame).
  void setHandScript(const std::vector<HandKeyMm>& keys, const Placement& frame,
                     const std::array<double, 3>& pivot_mm);
  double scriptDuration() const;
  // Or: a hand the front end sets (setHand, mm); silent after hold_s without a new hand.
  void useHandInput(double hold_s = 0.5);
  // setHand() also feeds the simulated arm's target (below) when that is the device.
  void setHand(const std::array<double, 3>& index_mm, const std::array<double, 3>& thumb_mm,
               const std::array<double, 3>& wrist_mm);
  // Or: the simulated master arm (resources/arms/master_arm.urdf) whose simulated operator
  // pulls the arm's hand towards the hand setHand() gives (the target, mm); the grasp sees
  // the arm's fingertips and its forces are mapped to the arm's joints. The arm is placed
  // so that its resting grip centre is at rest_mm and its resting grip axis (thumb -> index)
  // along the horizontal direction grip_axis (zero: the arm's own); silent hold_s after
  // the last setHand(). Made now (loads the URDF): setHand() may be called before start().
  void useSimulatedArm(const std::array<double, 3>& rest_mm, const std::array<double, 3>& grip_axis,
                       double hold_s = 0.5);
  // The chosen arm's hand at rest (index, thumb, wrist, mm), its grip axis (unit,
  // thumb -> index, horizontal). Throws std::logic_error when the arm is not the device.
  struct ArmRest {
    std::array<double, 3> index_mm{}, thumb_mm{}, wrist_mm{}, gripAxis{};
  };
  ArmRest armRest() const;
  // Or: a SpaceMouse (path empty: the first attached), opened now; its grip centre starts
  // at start_mm, the grip opens to open_mm and pinches to closed_mm (button 1 pinches,
  // button 2 opens). Input only: no forces are displayed, the grasp still works.
  // Throws device::HidError (none attached, cannot be opened: the message says how to fix
  // it); the session's device is then unchanged.
  void useSpaceMouse(const std::string& path, const std::array<double, 3>& start_mm, double open_mm,
                     double closed_mm);
  // Or: the HID device a JSON layout describes (path empty: the first attached device the
  // layout matches), its frame's origin placed at origin_mm. Throws HidLayoutError for a
  // bad layout, HidError as above.
  void useHid(const std::string& layoutFile, const std::string& path, const std::array<double, 3>& origin_mm);
  std::string deviceName() const;
  // False for an input-only device (SpaceMouse, the hand input, a layout without a force
  // output report): the snapshot's forces are computed but nobody feels them.
  bool deviceForceOutput() const;

  // The force parameters the front end may set (SI): K_c, B_c, K_g, B_g, d_h, K_ox, K_oe.
  static const std::vector<std::string>& parameterNames();
  // Before start(). Sets the given keys (the others keep their values) and validates the
  // whole set with GraspParameters::validate(); nothing changes if it throws
  // std::invalid_argument (an unknown key, or the validation's message naming the key).
  void setParameters(const std::vector<std::pair<std::string, double>>& values);
  const grasp::GraspParameters& parameters() const { return parameters_; }
  double parameter(const std::string& name) const;

  // Before start(): "two-finger" (the first paper's state machine, the default) or
  // "multi-finger" (the resultant-force paper's method, with as many fingertips as the
  // device reads). Throws std::invalid_argument for another name.
  void setMethod(const std::string& method);
  const std::string& method() const { return method_; }
  // Before start(): whether a carried part meets the others (stops at contact, slides;
  // the hand feels it) or passes through them (its clearance and any interference are
  // still reported). On by default; every part's contact shell is built with its model
  // either way.
  void setContact(bool on);
  bool contact() const { return contact_; }

  void start(double rate_hz = 2000, bool realtime = true);

  // Scene mode: instead of addPart/addBuilt then start(), the servo starts at once on the
  // parts' stand-ins (their boxes), and each distinct shape's model is built in the
  // background, once, nearest the hand first, as its shape is provided. Throws
  // std::invalid_argument (no parts, a bad box or placement, no device).
  void startScene(const std::vector<SceneRequest>& parts, double rate_hz = 2000, bool realtime = true,
                  int workers = 1);
  bool sceneMode() const { return build_ != nullptr; }
  // The models still waiting for their shape, nearest the hand first (at most `limit`); the
  // part whose shape to export for each: its first part.
  std::vector<std::size_t> wantedShapes(std::size_t limit) const;
  std::size_t modelOfPart(std::size_t part) const;
  std::size_t firstPartOfModel(std::size_t model) const;
  // Model m's shape, BREP text in mm without placement (parsed on a worker).
  void provideShape(std::size_t model, std::string brep);
  SceneStatus sceneStatus() const;
  // Scene mode, any time: part `part`'s shape was edited; it gets the model a finished
  // one-part ModelBuild built, from the servo's next tick (no restart: a held part keeps
  // the weight it was lifted with). Returns the new model's summary.
  PartInfo replaceScenePart(std::size_t part, ModelBuild& build);
  // Where model m came from: "built", "memory" or "disk" (the model cache), "rebuilt
  // (why)" for a cache entry not trusted; "" while waiting.
  std::string modelSource(std::size_t model) const;
  // A built model's summary (its first part's mass), or its error (`error` set).
  PartInfo modelInfo(std::size_t model, std::string* error = nullptr) const;
  // Stops the servo loop, then the recorder (so that its drop count is final).
  void stop() noexcept;
  bool running() const { return loop_ && loop_->running(); }

  // Before start()/startScene(): record the session into `path` (MCAP; "" records nothing),
  // `document` naming the FreeCAD document in the recording. A file that cannot be created
  // does not stop the session: recordingStatus().error says why.
  void recordTo(const std::string& path, const std::string& document);
  // A reviewer's note at the loop's latest snapshot time, about the part under the hand;
  // or at a mark taken earlier (the moment the reviewer pressed N, before typing the note).
  // Throws std::logic_error when not recording.
  struct NoteMark {
    double time_s = 0;
    std::string part;
  };
  NoteMark markNote();
  void annotate(const std::string& text);
  void annotate(const std::string& text, const NoteMark& mark);
  RecordingStatus recordingStatus() const;
  // The running (or last) servo loop's scheduling and timing.
  ServoTiming servoTiming() const;

  SessionSnapshot snapshot();

  // Fault injection for tests and demos: the device goes silent (or speaks again).
  void setDeviceSilent(bool silent);
  void resetGrasp();

 private:
  std::vector<grasp::ScenePart> parts_;
  std::vector<PartInfo> infos_;
  grasp::GraspParameters parameters_;
  grasp::multi_finger::MultiFingerParams multiFinger_;  // the multi-finger method's k, k_d, μ, γ
  std::unique_ptr<grasp::HandScript> script_;
  double handHold_s_ = 0;  // > 0: the hand input device was chosen
  std::shared_ptr<servo::ScriptedHandDevice> scripted_;
  std::shared_ptr<HandInputDevice> input_;
  std::shared_ptr<ArmInputDevice> arm_;  // the simulated arm, made when chosen
  std::shared_ptr<device::Device> device_;  // the one start() made, reused by restart()
  servo::ServoConfig config_;
  double timeOffset_s_ = 0;                 // servo time of the loops before a restart()
  std::uint64_t tickOffset_ = 0;
  std::shared_ptr<PlacedDevice> hid_;  // SpaceMouse or HID layout, opened when chosen
  std::string method_ = "two-finger";
  bool contact_ = true;
  std::unique_ptr<servo::GraspEngine> makeEngine(const grasp::ScenePtr& scene) const;
  std::unique_ptr<servo::ServoLoop> loop_;
  std::string realtimeAdvice_;  // set when the loop asked for SCHED_FIFO and was refused
  std::unique_ptr<servo::ServoSnapshot> snap_ = std::make_unique<servo::ServoSnapshot>();
  servo::SnapshotReader reader_;
  servo::PoseTracker tracker_;  // every part's pose, from the snapshots' moving parts and put-downs
  void resetTracker();
  bool hasDevice() const;
  void launch(const grasp::ScenePtr& scene, const servo::ServoConfig& config);
  void runLoop(const grasp::ScenePtr& scene);  // a new loop on `scene`, recorded, started
  grasp::multi_finger::MultiFingerSceneParams multiFingerParams() const;
  std::string partName(std::size_t i) const;
  std::string partUnderHand(const servo::ServoSnapshot& s) const;

  // Recording: the current file's recorder; recorded_ sums the files closed before it.
  std::string recordPath_, recordDocument_;
  std::unique_ptr<session::Recorder> recorder_;
  RecordingStatus recorded_;
  grasp::ScenePtr scene_;  // the running loop's scene (annotate's nearest part)
  session::SessionDescription describeSession(const grasp::ScenePtr& scene) const;
  void startRecording(const grasp::ScenePtr& scene);
  void endRecording() noexcept;
  std::vector<grasp::PartPose> initialPoses() const;
  void refreshBackends();  // scene mode: the backends of parts whose model came in

  std::unique_ptr<grasp::SceneBuild> build_;  // scene mode
  std::vector<SceneRequest> sceneRequests_;
  std::vector<std::pair<std::string, std::string>> backends_;  // scene mode, per part
  std::vector<bool> describedModel_;
  struct CacheSources {  // written by the build's workers
    std::mutex mutex;
    std::map<std::size_t, std::string> byModel;
  };
  std::shared_ptr<CacheSources> cacheSources_ = std::make_shared<CacheSources>();
  // Set when the session ends: a scene model in the loader process is not waited for (its
  // build's workers are joined next).
  std::shared_ptr<std::atomic<bool>> loadsCancelled_ = std::make_shared<std::atomic<bool>>(false);
  std::size_t exactParts_ = 0;
};

}  // namespace hg::freecad
