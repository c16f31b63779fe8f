// _hapticgrasp: the thin pybind11 binding of the FreeCAD workbench. Lengths cross it in
// mm (FreeCAD's unit); freecad_boundary.cpp converts them, nothing here does. Long calls
// (parsing and validating B-reps, starting/stopping the servo thread) release the GIL.
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <optional>

#include "freecad_boundary.hpp"
#include "haptic_session.hpp"
#include "hapticgrasp/geometry/backends.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/model_cache.hpp"
#include "hid_input.hpp"
#include "part_loader.hpp"
#include "hapticgrasp/session/recording.hpp"
#include "hapticgrasp/session/review_track.hpp"
#include "hapticgrasp/session/session_series.hpp"

namespace py = pybind11;
using namespace hg;
using hg::freecad::Placement;

namespace {

Placement placementFrom(const std::array<double, 3>& base_mm, const std::array<double, 4>& quaternion) {
  return Placement{base_mm, quaternion};
}

py::tuple toTuple(const Placement& p) {
  return py::make_tuple(py::make_tuple(p.base_mm[0], p.base_mm[1], p.base_mm[2]),
                        py::make_tuple(p.quaternion[0], p.quaternion[1], p.quaternion[2], p.quaternion[3]));
}

geometry::MassSpec massSpec(std::optional<double> density, std::optional<double> mass) {
  if (density && mass) throw std::invalid_argument("give a density or a mass, not both");
  if (mass) return geometry::MassSpec::mass(*mass);
  return geometry::MassSpec::density(density.value_or(1000.0));
}

py::dict infoDict(const freecad::PartInfo& info) {
  py::dict d;
  d["name"] = info.name;
  d["faces"] = info.faces;
  d["volume_mm3"] = info.volume_mm3;
  d["mass_kg"] = info.mass_kg;
  d["centre_mm"] = py::make_tuple(info.centre_mm[0], info.centre_mm[1], info.centre_mm[2]);
  d["primitive"] = info.primitive;
  d["warnings"] = info.warnings;
  d["backend"] = info.backend;
  d["backend_reason"] = info.backendReason;
  d["load_s"] = info.load_s;
  d["check_s"] = info.check_s;
  const auto mm = [](const std::array<double, 3>& p) { return py::make_tuple(p[0], p[1], p[2]); };
  d["bounds_mm"] = py::make_tuple(mm(info.boundsMin_mm), mm(info.boundsMax_mm));
  return d;
}

// (name, brep, base_mm, quaternion, density) or with a 6th item, mass (density None).
freecad::PartRequest partRequest(const py::handle& item) {
  const auto t = py::reinterpret_borrow<py::tuple>(item);
  if (t.size() != 5 && t.size() != 6)
    throw std::invalid_argument("a part to build is (name, brep, base_mm, quaternion, density[, mass])");
  std::optional<double> density, mass;
  if (!t[4].is_none()) density = t[4].cast<double>();
  if (t.size() == 6 && !t[5].is_none()) mass = t[5].cast<double>();
  return freecad::PartRequest{t[0].cast<std::string>(), t[1].cast<std::string>(),
                              placementFrom(t[2].cast<std::array<double, 3>>(), t[3].cast<std::array<double, 4>>()),
                              massSpec(density, mass)};
}

}  // namespace

PYBIND11_MODULE(_hapticgrasp, m) {
  m.doc() = "HapticGrasp core for the FreeCAD workbench (lengths in mm, quaternions as FreeCAD's Rotation.Q)";
  py::register_exception<geometry::GeometryError>(m, "GeometryError", PyExc_ValueError);
  // A HID device that is not attached or cannot be opened (the message says how to fix it).
  py::register_exception<device::HidError>(m, "DeviceError", PyExc_RuntimeError);
  // A HID layout file that does not load or make sense (the message names the field).
  py::register_exception<device::HidLayoutError>(m, "LayoutError", PyExc_ValueError);

  m.def(
      "list_devices",
      [](const std::vector<std::string>& layoutDirs) {
        freecad::HidListing listing;
        {
          py::gil_scoped_release release;
          listing = freecad::listHidDevices(layoutDirs);
        }
        py::list devices;
        for (const auto& d : listing.devices) {
          py::dict e;
          e["path"] = d.info.path;
          e["vendor_id"] = d.info.vendor_id;
          e["product_id"] = d.info.product_id;
          e["product"] = d.info.product;
          e["manufacturer"] = d.info.manufacturer;
          e["backend"] = device::hidBackendName(d.backend);
          e["model"] = d.model;
          e["layout"] = d.layoutIndex >= 0 ? listing.layouts[d.layoutIndex].source : std::string();
          devices.append(e);
        }
        py::dict out;
        out["devices"] = devices;
        out["layout_errors"] = listing.layoutErrors;
        return out;
      },
      py::arg("layout_dirs") = std::vector<std::string>{},
      "The HID devices attached: {'devices': [{path, vendor_id, product_id, product, manufacturer, backend "
      "('spacemouse', 'layout' or 'none'), model, layout (the matching layout file)}], 'layout_errors': [...]}, "
      "with the *.json layouts of layout_dirs.");

  // TEST ONLY: an in-process fake HID transport in place of hidapi (this kernel cannot
  // make virtual HID devices). Not for use outside tests.
  py::class_<freecad::TestHidFeed, std::shared_ptr<freecad::TestHidFeed>>(m, "_TestHidFeed")
      .def(
          "add_device",
          [](freecad::TestHidFeed& f, const std::string& path, std::uint16_t vendor_id, std::uint16_t product_id,
             const std::string& product) {
            device::HidDeviceInfo info;
            info.path = path;
            info.vendor_id = vendor_id;
            info.product_id = product_id;
            info.product = product;
            f.addDevice(info);
          },
          py::arg("path"), py::arg("vendor_id"), py::arg("product_id"), py::arg("product") = "")
      .def("remove_device", &freecad::TestHidFeed::removeDevice)
      .def(
          "queue_report",
          [](freecad::TestHidFeed& f, const std::string& path, const py::bytes& data) {
            const std::string bytes = data;
            f.queueReport(path, std::vector<std::uint8_t>(bytes.begin(), bytes.end()));
          },
          py::arg("path"), py::arg("report"))
      .def("pending", &freecad::TestHidFeed::pending);
  m.def(
      "_use_fake_hid",
      []() {
        auto feed = std::make_shared<freecad::TestHidFeed>();
        freecad::useTestHidTransport(feed);
        return feed;
      },
      "TEST ONLY: replace hidapi with an in-process fake transport (returned; add devices and queue reports on it).");
  m.def("_use_real_hid", &freecad::useRealHidTransport, "TEST ONLY: back to hidapi after _use_fake_hid().");

  m.def(
      "part_info",
      [](const std::string& brep, const std::string& name, std::optional<double> density, std::optional<double> mass) {
        const geometry::MassSpec spec = massSpec(density, mass);
        freecad::PartInfo info;
        {
          py::gil_scoped_release release;
          const geometry::PartModelPtr part = freecad::loadPart(brep, name);
          info = freecad::describe(*part, spec, *geometry::makePenetration(part));
        }
        return infoDict(info);
      },
      py::arg("brep"), py::arg("name") = "part", py::arg("density") = py::none(), py::arg("mass") = py::none(),
      "Validate BREP text (mm, Placement reset) and return faces, volume_mm3, mass_kg, centre_mm, primitive, warnings, "
      "backend and backend_reason (which penetration back end answers it and why, one line), load_s and check_s. "
      "Raises GeometryError (a ValueError) for a shape that cannot be grasped.");

  py::class_<freecad::ModelBuild>(m, "ModelBuild",
                                  "Builds part models on a worker thread (the GIL is not held by it); poll progress().")
      .def(py::init([](const py::list& parts, bool open) {
             std::vector<freecad::PartRequest> requests;
             for (const auto& item : parts) requests.push_back(partRequest(item));
             return std::make_unique<freecad::ModelBuild>(std::move(requests), open);
           }),
           py::arg("parts"), py::arg("open") = false,
           "Starts building at once. parts: [(name, brep, base_mm, quaternion, density[, mass])], BREP text in mm "
           "without the Placement. open=True: more parts come with add() until close().")
      .def(
          "add", [](freecad::ModelBuild& b, const py::tuple& part) { b.add(partRequest(part)); }, py::arg("part"),
          "An open build: one more part, (name, brep, base_mm, quaternion, density[, mass]).")
      .def("close", &freecad::ModelBuild::close, "An open build takes no more parts; it finishes when they are built.")
      .def(
          "progress",
          [](const freecad::ModelBuild& b) {
            const auto p = b.progress();
            py::dict d;
            d["done"] = p.done;
            d["total"] = p.total;
            d["current"] = p.current;
            d["finished"] = p.finished;
            d["cancelled"] = p.cancelled;
            return d;
          },
          "done, total, current (the part being built), finished, cancelled.")
      .def("cancel", &freecad::ModelBuild::cancel, "Stops after the part in progress; nothing built is added.")
      .def("wait", &freecad::ModelBuild::wait, py::arg("timeout_s") = -1.0, py::call_guard<py::gil_scoped_release>(),
           "Blocks (GIL released) until finished or timeout_s (< 0: no limit); True when finished.")
      .def(
          "errors",
          [](const freecad::ModelBuild& b) {
            py::list out;
            for (const auto& o : b.outcomes())
              if (!o.error.empty()) out.append(py::make_tuple(o.request, o.name, o.error));
            return out;
          },
          "[(request index, name, message)] of the parts that could not be built.");

  py::class_<freecad::Session>(m, "Session")
      .def(py::init<>())
      .def(
          "add_part",
          [](freecad::Session& s, const std::string& name, const std::string& brep, const std::array<double, 3>& base_mm,
             const std::array<double, 4>& quaternion, std::optional<double> density, std::optional<double> mass) {
            const geometry::MassSpec spec = massSpec(density, mass);
            const Placement placement = placementFrom(base_mm, quaternion);
            py::gil_scoped_release release;
            return s.addPart(name, brep, placement, spec);
          },
          py::arg("name"), py::arg("brep"), py::arg("base_mm"), py::arg("quaternion"), py::arg("density") = py::none(),
          py::arg("mass") = py::none(), "Add a part (BREP text in mm without Placement); returns its index.")
      .def(
          "add_built",
          [](freecad::Session& s, freecad::ModelBuild& build) {
            py::list out;
            for (const auto& [request, index] : s.addBuilt(build)) out.append(py::make_tuple(request, index));
            return out;
          },
          py::arg("build"),
          "Before start(): adds every part a finished ModelBuild built; returns [(request index, part index)].")
      .def("replace_part", &freecad::Session::replacePart, py::arg("index"), py::arg("build"),
           "Part `index` gets the part a finished one-part ModelBuild built; a running loop needs restart().")
      .def(
          "restart",
          [](freecad::Session& s, const std::vector<std::pair<std::array<double, 3>, std::array<double, 4>>>& placements) {
            std::vector<Placement> p;
            for (const auto& [base, q] : placements) p.push_back(placementFrom(base, q));
            py::gil_scoped_release release;
            s.restart(p);
          },
          py::arg("placements"),
          "While running: a new servo loop with the current parts at `placements` (((x, y, z) mm, (qx, qy, qz, qw)) "
          "per part), same device and parameters; the grasp starts again from FREE.")
      .def("part_count", &freecad::Session::partCount)
      .def("part_info", [](const freecad::Session& s, std::size_t i) { return infoDict(s.partInfo(i)); })
      .def(
          "set_hand_script",
          [](freecad::Session& s, const std::vector<py::tuple>& keys, const std::array<double, 3>& frame_base_mm,
             const std::array<double, 4>& frame_quaternion, std::optional<std::array<double, 3>> pivot_mm) {
            std::vector<freecad::HandKeyMm> k;
            for (const auto& key : keys) {
              if (key.size() != 6) throw std::invalid_argument("a hand key is (t, index_mm, thumb_mm, wrist_mm, shift_mm, turn)");
              freecad::HandKeyMm h;
              h.t = key[0].cast<double>();
              h.index_mm = key[1].cast<std::array<double, 3>>();
              h.thumb_mm = key[2].cast<std::array<double, 3>>();
              h.wrist_mm = key[3].cast<std::array<double, 3>>();
              h.shift_mm = key[4].cast<std::array<double, 3>>();
              h.turn = key[5].cast<double>();
              k.push_back(h);
            }
            s.setHandScript(k, placementFrom(frame_base_mm, frame_quaternion), pivot_mm.value_or(frame_base_mm));
          },
          py::arg("keys"), py::arg("frame_base_mm") = std::array<double, 3>{0, 0, 0},
          py::arg("frame_quaternion") = std::array<double, 4>{0, 0, 0, 1}, py::arg("pivot_mm") = py::none(),
          "The device: a scripted hand. keys: (t_s, index_mm, thumb_mm, wrist_mm, shift_mm, turn_rad) tuples; "
          "turns are about the vertical through pivot_mm (default: the frame's origin).")
      .def("script_duration", &freecad::Session::scriptDuration)
      .def("use_hand_input", &freecad::Session::useHandInput, py::arg("hold_s") = 0.5,
           "The device: a hand set with set_hand(); silent hold_s after the last set_hand().")
      .def("set_hand", &freecad::Session::setHand, py::arg("index_mm"), py::arg("thumb_mm"), py::arg("wrist_mm"),
           "Any one thread: the hand now (absolute frame, mm); lock-free.")
      .def("use_simulated_arm", &freecad::Session::useSimulatedArm, py::arg("rest_mm"),
           py::arg("grip_axis") = std::array<double, 3>{0, 0, 0}, py::arg("hold_s") = 0.5,
           "The device: the simulated master arm, its resting grip centre placed at rest_mm (document, mm), its "
           "grip axis (thumb -> index) turned about the vertical onto the horizontal direction grip_axis "
           "(zero: the arm's own). "
           "set_hand() then sets the simulated operator's target (mm); the grasp sees the arm's fingertips "
           "and its forces go to the arm's joints. Silent hold_s after the last set_hand(). The hand opens to "
           "about 100 mm; arm_rest() gives its resting hand.")
      .def(
          "arm_rest",
          [](const freecad::Session& s) {
            const auto r = s.armRest();
            py::dict d;
            d["index"] = py::make_tuple(r.index_mm[0], r.index_mm[1], r.index_mm[2]);
            d["thumb"] = py::make_tuple(r.thumb_mm[0], r.thumb_mm[1], r.thumb_mm[2]);
            d["wrist"] = py::make_tuple(r.wrist_mm[0], r.wrist_mm[1], r.wrist_mm[2]);
            d["grip_axis"] = py::make_tuple(r.gripAxis[0], r.gripAxis[1], r.gripAxis[2]);
            return d;
          },
          "The simulated arm's hand at rest (index, thumb, wrist: mm, document) and its grip axis (unit, "
          "horizontal, thumb -> index). Raises RuntimeError when the arm is not the device.")
      .def("use_spacemouse", &freecad::Session::useSpaceMouse, py::arg("path") = "",
           py::arg("start_mm") = std::array<double, 3>{0, 0, 0}, py::arg("open_mm") = 80.0, py::arg("closed_mm") = 0.0,
           "The device: a SpaceMouse (path '': the first attached), opened now. Its grip centre starts at start_mm "
           "(document, mm), opens to open_mm, button 1 pinches to closed_mm, button 2 opens. Input only: no "
           "forces are displayed. Raises DeviceError (a RuntimeError) when none is attached or it cannot be "
           "opened (the message says how to fix it); the session's device is then unchanged.")
      .def("use_hid", &freecad::Session::useHid, py::arg("layout"), py::arg("path") = "",
           py::arg("origin_mm") = std::array<double, 3>{0, 0, 0},
           "The device: the HID device the JSON layout file describes (path '': the first attached device it "
           "matches), its frame's origin at origin_mm (document, mm). Raises LayoutError (a ValueError) for a bad "
           "layout, DeviceError as use_spacemouse.")
      .def_property_readonly("device_name", &freecad::Session::deviceName)
      .def_property_readonly("device_force_output", &freecad::Session::deviceForceOutput,
                             "False for an input-only device: the snapshot's forces are computed, not displayed.")
      .def(
          "set_parameters",
          [](freecad::Session& s, const py::dict& values) {
            std::vector<std::pair<std::string, double>> v;
            for (const auto& item : values) {
              const std::string name = py::str(item.first);
              double value = 0;
              try {
                if (py::isinstance<py::str>(item.second)) throw py::cast_error();
                value = py::float_(py::reinterpret_borrow<py::object>(item.second));
              } catch (const py::error_already_set&) {
                throw py::value_error("grasp parameter " + name + " must be a number, not " +
                                      std::string(py::repr(item.second)));
              } catch (const py::cast_error&) {
                throw py::value_error("grasp parameter " + name + " must be a number, not " +
                                      std::string(py::repr(item.second)));
              }
              v.emplace_back(name, value);
            }
            s.setParameters(v);
          },
          py::arg("values"),
          "Before start(): force parameters in SI, a dict with any of K_c, B_c, K_g, B_g, d_h, K_ox, K_oe (the "
          "two-finger method) and k, k_d, mu, gamma1, gamma2, gamma3 (the multi-finger method); the others keep "
          "their values. Validated by the core; raises ValueError naming the key.")
      .def(
          "parameters",
          [](const freecad::Session& s) {
            py::dict d;
            for (const auto& name : freecad::Session::parameterNames()) d[py::str(name)] = s.parameter(name);
            return d;
          },
          "The parameters the session starts with (SI): K_c, B_c, K_g, B_g, d_h, K_ox, K_oe, k, k_d, mu, gamma1, "
          "gamma2, gamma3.")
      .def("set_method", &freecad::Session::setMethod, py::arg("method"),
           "Before start(): 'two-finger' (default) or 'multi-finger' (the resultant-force method, as many "
           "fingertips as the device reads).")
      .def_property_readonly("method", &freecad::Session::method)
      .def("set_contact", &freecad::Session::setContact, py::arg("on"),
           "Before start(): whether a carried part meets the others (stops at contact and slides, the hand "
           "feels it; the default) or passes through them.")
      .def_property_readonly("contact", &freecad::Session::contact)
      .def("start", &freecad::Session::start, py::arg("rate_hz") = 2000.0, py::arg("realtime") = true,
           py::call_guard<py::gil_scoped_release>())
      .def(
          "start_scene",
          [](freecad::Session& s, const py::list& parts, double rate_hz, bool realtime, int workers) {
            std::vector<freecad::SceneRequest> requests;
            requests.reserve(parts.size());
            for (const py::handle& item : parts) {
              const auto t = py::reinterpret_borrow<py::tuple>(item);
              if (t.size() != 7)
                throw std::invalid_argument(
                    "a scene part is (name, key, box_min_mm, box_max_mm, base_mm, quaternion, density)");
              freecad::SceneRequest r;
              r.name = t[0].cast<std::string>();
              r.key = t[1].cast<std::string>();
              r.boxMin_mm = t[2].cast<std::array<double, 3>>();
              r.boxMax_mm = t[3].cast<std::array<double, 3>>();
              r.placement = placementFrom(t[4].cast<std::array<double, 3>>(), t[5].cast<std::array<double, 4>>());
              r.mass = massSpec(t[6].is_none() ? std::nullopt : std::optional<double>(t[6].cast<double>()), std::nullopt);
              requests.push_back(std::move(r));
            }
            py::gil_scoped_release release;
            s.startScene(requests, rate_hz, realtime, workers);
          },
          py::arg("parts"), py::arg("rate_hz") = 2000.0, py::arg("realtime") = true, py::arg("workers") = 1,
          "Scene mode: starts the servo at once on every part's bounding box; parts are (name, key, box_min_mm, "
          "box_max_mm, base_mm, quaternion, density), the box in the part's own frame, the key shared by "
          "identical shapes. Each distinct shape's model is built in the background once its shape comes "
          "(wanted_shapes, provide_shape), nearest the hand first.")
      .def_property_readonly("scene_mode", &freecad::Session::sceneMode)
      .def(
          "replace_scene_part",
          [](freecad::Session& s, std::size_t part, freecad::ModelBuild& build) {
            return infoDict(s.replaceScenePart(part, build));
          },
          py::arg("part"), py::arg("build"),
          "Scene mode: part `part` (its shape edited) is felt through the model a finished one-part ModelBuild "
          "built, from the next servo tick; returns its part_info.")
      .def("wanted_shapes", &freecad::Session::wantedShapes, py::arg("limit") = 8,
           "Scene mode: the models waiting for their shape, nearest the hand first.")
      .def("model_of_part", &freecad::Session::modelOfPart, py::arg("part"))
      .def("first_part_of_model", &freecad::Session::firstPartOfModel, py::arg("model"))
      .def("provide_shape", &freecad::Session::provideShape, py::arg("model"), py::arg("brep"),
           "Scene mode: model's shape, BREP text in mm without placement (parsed and checked on a worker).")
      .def("scene_status",
           [](const freecad::Session& s) {
             const freecad::SceneStatus st = s.sceneStatus();
             py::dict d;
             d["parts"] = st.parts;
             d["models"] = st.models;
             d["built"] = st.built;
             d["failed"] = st.failed;
             d["exact_parts"] = st.exactParts;
             d["finished"] = st.finished;
             return d;
           })
      .def(
          "model_info",
          [](const freecad::Session& s, std::size_t model) {
            std::string error;
            py::dict d = infoDict(s.modelInfo(model, &error));
            d["error"] = error;
            d["source"] = s.modelSource(model);
            return d;
          },
          py::arg("model"),
          "Scene mode: a model's summary as part_info gives it, 'error' if it failed, and 'source': built, memory "
          "or disk (the model cache), rebuilt (a cache entry not trusted, and why).")
      .def("stop", &freecad::Session::stop, py::call_guard<py::gil_scoped_release>())
      .def("record_to", &freecad::Session::recordTo, py::arg("path"), py::arg("document") = "",
           "Before start(): record the session into `path` (MCAP; '' records nothing). restart() goes on in "
           "'<name>-2.mcap' beside it. A file that cannot be created leaves haptics running: "
           "recording_status()['error'] says why.")
      .def(
          "mark_note",
          [](freecad::Session& s) {
            const freecad::Session::NoteMark mark = s.markNote();
            return py::make_tuple(mark.time_s, mark.part);
          },
          "(servo time s, part under the hand): where a note begun now belongs (annotate's mark).")
      .def(
          "annotate",
          [](freecad::Session& s, const std::string& text, std::optional<std::pair<double, std::string>> mark) {
            if (mark) s.annotate(text, {mark->first, mark->second});
            else s.annotate(text);
          },
          py::arg("text"), py::arg("mark") = py::none(),
          "A reviewer's note at the servo's current time (or at `mark`, from mark_note() when the reviewer "
          "began it), about the part under the hand (the grasped one, else the nearest within 30 mm of the grip "
          "centre, else none). Raises RuntimeError when not recording.")
      .def(
          "servo_timing",
          [](const freecad::Session& s) {
            const freecad::ServoTiming t = s.servoTiming();
            py::dict d, err;
            err["p50"] = t.periodErrP50_us;
            err["p99"] = t.periodErrP99_us;
            err["max"] = t.periodErrMax_us;
            d["target_hz"] = t.target_hz;
            d["achieved_hz"] = t.achieved_hz;
            d["period_err_us"] = err;
            d["ticks"] = t.ticks;
            d["scheduler"] = t.scheduler;
            d["memory_lock"] = t.memoryLock;
            d["realtime"] = t.realtime;
            d["advice"] = t.advice;
            return d;
          },
          "The servo thread: target_hz, achieved_hz, period_err_us {p50, p99, max}, ticks, scheduler and "
          "memory_lock as the loop got them, realtime (SCHED_FIFO granted) and advice (why not, and the fix).")
      .def(
          "recording_status",
          [](const freecad::Session& s) {
            const freecad::RecordingStatus st = s.recordingStatus();
            py::dict d;
            d["path"] = st.path;
            d["files"] = st.files;
            d["recording"] = st.recording;
            d["error"] = st.error;
            d["ticks"] = st.ticks;
            d["dropped"] = st.dropped;
            d["bytes"] = st.bytes;
            d["annotations"] = st.annotations;
            d["duration_s"] = st.duration_s;
            return d;
          },
          "path (the current or last file), files (every file), recording, error, and over every file: ticks, "
          "dropped (ticks lost), bytes, annotations, duration_s.")
      .def_property_readonly("running", &freecad::Session::running)
      .def("set_device_silent", &freecad::Session::setDeviceSilent)
      .def("reset_grasp", &freecad::Session::resetGrasp)
      .def(
          "snapshot",
          [](freecad::Session& s) {
            const freecad::SessionSnapshot snap = s.snapshot();
            py::dict d;
            d["tick"] = snap.tick;
            d["time_s"] = snap.time_s;
            d["state"] = snap.state;
            d["grasped"] = snap.graspedPart;
            d["events"] = snap.events;
            d["event_names"] = snap.eventNames;
            d["events_lost"] = snap.eventsLost;
            d["fault"] = snap.fault;
            d["faults"] = snap.faults;
            py::list placements;
            for (const auto& p : snap.placements) placements.append(toTuple(p));
            d["placements"] = placements;
            d["forces"] = py::make_tuple(py::make_tuple(snap.forces_N[0][0], snap.forces_N[0][1], snap.forces_N[0][2]),
                                         py::make_tuple(snap.forces_N[1][0], snap.forces_N[1][1], snap.forces_N[1][2]));
            d["grasp_force_n"] = snap.graspForce_N;
            const auto mm = [](const std::array<double, 3>& p) { return py::make_tuple(p[0], p[1], p[2]); };
            d["hand"] = py::make_tuple(mm(snap.index_mm), mm(snap.thumb_mm), mm(snap.wrist_mm));
            py::list tips, tipForces;
            for (std::size_t k = 0; k < snap.fingertips_mm.size(); ++k) {
              tips.append(mm(snap.fingertips_mm[k]));
              tipForces.append(mm(snap.fingertipForces_N[k]));
            }
            d["fingertips"] = tips;
            d["fingertip_forces"] = tipForces;
            d["method"] = snap.method;
            d["rate_hz"] = snap.rate_hz;
            d["jitter_us"] = snap.jitter_us;
            py::list backends;
            for (const auto& [backend, reason] : snap.backends) backends.append(py::make_tuple(backend, reason));
            d["backends"] = backends;
            d["exact_parts"] = snap.exactParts;
            const freecad::SessionSnapshot::Contact& c = snap.contact;
            if (c.carried || c.unmodelled > 0) {
              py::dict k;
              k["part"] = c.part;
              k["other_part"] = c.otherPart;
              k["clearance_mm"] = c.clearance_mm;
              k["exact"] = c.exact;
              k["held_face"] = c.heldFace;
              k["other_face"] = c.otherFace;
              k["held_point"] = mm(c.heldPoint_mm);
              k["other_point"] = mm(c.otherPoint_mm);
              k["penetration_mm"] = c.penetration_mm;
              k["contact_force_n"] = c.contactForce_N;
              k["active"] = c.active;
              k["lagging"] = c.lagging;
              k["saturated"] = c.saturated;
              k["unmodelled"] = c.unmodelled;
              k["let_through"] = c.letThrough;
              d["contact"] = k;
            } else {
              d["contact"] = py::none();
            }
            return d;
          },
          "state, grasped part, events since the previous snapshot, watchdog fault, every part's "
          "placement as ((x, y, z) mm, (qx, qy, qz, qw)), the fingertip forces felt (N), the "
          "grasping force (N), the hand (index, thumb, wrist; mm), every fingertip in use (mm) and "
          "its force (N), the method, the servo rate (Hz), its period jitter (p99, us), and every part's "
          "(penetration back end, why) in part order.");

  m.def("model_cache_dir", [] { return geometry::ModelCache::defaultDir().string(); },
        "Where checked part models are cached on disk ('' when off): $HAPTICGRASP_CACHE_DIR, else "
        "$XDG_CACHE_HOME/hapticgrasp/models, else ~/.cache/hapticgrasp/models.");
  m.def("clear_model_cache_memory", [] { geometry::ModelCache::shared().clearMemory(); },
        "Forgets the models kept in memory (the disk cache stays): as a new FreeCAD session would start.");

  // The loader process (src/part_loader.hpp): parts load outside FreeCAD.
  m.def(
      "loader",
      [] {
        const freecad::LoaderStatus s = freecad::loaderStatus();
        py::dict d;
        d["isolated"] = s.isolated;
        d["program"] = s.program;
        d["started"] = s.started;
        d["time_limit_s"] = s.timeLimit_s;
        d["why"] = s.why;
        return d;
      },
      "Where parts load: isolated (in the loader process, a crash or loop there costs FreeCAD nothing), "
      "program, started (helper processes so far), time_limit_s (per part), why (when not isolated).");
  m.def(
      "use_loader",
      [](const std::vector<std::string>& command, double time_limit_s) {
        freecad::useLoader(command, time_limit_s);
      },
      py::arg("command") = std::vector<std::string>{}, py::arg("time_limit_s") = 60.0,
      "Parts load in this program (with its arguments) from now on, each given up after time_limit_s; "
      "[] (the default): the installed loader. Tests hand a stand-in that crashes or hangs.");
  m.def("use_no_loader", &freecad::useNoLoader, py::arg("why") = "turned off",
        "Parts load in FreeCAD's own process from now on (a crash in OpenCASCADE then takes FreeCAD with it).");

  // Recordings (session/): what report.py and the Review panel read. The GIL is released:
  // a long recording reads on FreeCAD's side while the GUI keeps its events.
  m.def(
      "recording_info",
      [](const std::string& path) {
        py::gil_scoped_release release;
        return session::toJson(session::readRecordingInfo(path));
      },
      py::arg("path"),
      "What a recording holds, as JSON text (hapticgrasp recording info --json); raises RuntimeError "
      "for a file that is not a recording.");
  m.def(
      "read_session_series",
      [](const std::string& path, std::size_t maxBins) {
        py::gil_scoped_release release;
        return session::toJson(session::readSessionSeries(path, maxBins));
      },
      py::arg("path"), py::arg("max_bins") = 2000,
      "A recording reduced for a report, as JSON text (session_series.hpp): force, motion and timing "
      "series in at most max_bins bins (each the largest value in it), every event, the manipulations.");

  // The Review panel's recording (review.py): frames, pose keys, events, the last models.
  using session::ReviewTrack;
  const auto mmTuple = [](const Vec3& m) {
    const auto mm = freecad::toMillimetres(m);
    return py::make_tuple(mm[0], mm[1], mm[2]);
  };
  const auto nTuple = [](const Vec3& f) { return py::make_tuple(f.x(), f.y(), f.z()); };
  py::class_<ReviewTrack, std::shared_ptr<ReviewTrack>>(m, "ReviewTrack",
                                                      "A recording for the Review panel (open_review()).")
      .def_property_readonly("info_json", [](const ReviewTrack& r) { return session::toJson(r.info); })
      .def_property_readonly("duration_s", [](const ReviewTrack& r) { return r.frames.back().time_s; })
      .def_property_readonly("frame_count", [](const ReviewTrack& r) { return r.frames.size(); })
      .def("frame_times",
           [](const ReviewTrack& r) {
             std::vector<double> t;
             t.reserve(r.frames.size());
             for (const auto& f : r.frames) t.push_back(f.time_s);
             return t;
           })
      .def("frame_at", &ReviewTrack::frameAt, py::arg("t"), "The last frame at or before t (s).")
      .def(
          "frame",
          [mmTuple, nTuple](const ReviewTrack& r, std::size_t i) {
            const session::ReviewFrame& f = r.frames.at(i);
            py::dict d;
            d["time_s"] = f.time_s;
            d["state"] = grasp::toString(f.state);
            d["fault"] = f.fault;
            d["grasped"] = f.graspedPart;
            d["hand"] = py::make_tuple(mmTuple(f.fingertip_m[0]), mmTuple(f.fingertip_m[1]), mmTuple(f.wrist_m));
            d["forces"] = py::make_tuple(nTuple(f.force_N[0]), nTuple(f.force_N[1]));
            py::list tips, tipForces;
            for (int k = 0; k < f.fingertips; ++k) {
              tips.append(mmTuple(f.fingertip_m[k]));
              tipForces.append(nTuple(f.force_N[k]));
            }
            d["fingertips"] = tips;
            d["fingertip_forces"] = tipForces;
            d["grasp_force_n"] = f.grasp_N;
            return d;
          },
          py::arg("i"),
          "time_s, state, fault, grasped, hand (index, thumb, wrist; mm), forces (index, thumb; N, as sent), "
          "fingertips (mm) and fingertip_forces (N) of every fingertip in use, grasp_force_n.")
      .def_property_readonly(
          "parts",
          [mmTuple](const ReviewTrack& r) {
            py::list parts;
            const auto& recorded = r.info.description.parts;
            for (std::size_t i = 0; i < recorded.size(); ++i) {
              const session::RecordedPart& p = recorded[i];
              const session::RecordedPart& last = r.models.at(i);
              py::dict d;
              d["name"] = p.name;
              d["placement"] = toTuple(freecad::toPlacement(p.initialPose));
              d["faces"] = last.faces;
              d["volume_mm3"] = last.mass.volume_m3 * 1e9;
              d["centre_mm"] = mmTuple(last.mass.centre_m);
              d["bounds_mm"] = py::make_tuple(mmTuple(last.bounds.min), mmTuple(last.bounds.max));
              d["backend"] = last.backend;
              d["coarse"] = last.coarse;
              d["has_shape"] = !last.brep.empty();
              d["unit"] = last.unit == geometry::LengthUnit::Metre ? "m" : "mm";
              parts.append(d);
            }
            return parts;
          },
          "Per recorded part: name, placement (initial), and of its last recorded model: faces, volume_mm3, "
          "centre_mm (own frame), bounds_mm, backend, coarse, has_shape, unit (of its BREP).")
      .def_property_readonly("moved_parts", &ReviewTrack::movedParts)
      .def(
          "placements_at",
          [](const ReviewTrack& r, double t) {
            py::dict out;
            for (const int i : r.movedParts())
              out[py::int_(i)] = toTuple(freecad::toPlacement(r.poseAt(static_cast<std::size_t>(i), t)));
            return out;
          },
          py::arg("t"), "{part index: placement} of every part that moved, where it stood at time t (s).")
      .def(
          "part_brep",
          [](const ReviewTrack& r, std::size_t i) -> py::object {
            const session::RecordedPart& p = r.models.at(i);
            if (p.brep.empty()) return py::none();
            std::string text;
            {
              py::gil_scoped_release release;  // the part's checks: as long as loading it
              text = freecad::recordedShapeText(p);
            }
            return py::bytes(text);
          },
          py::arg("i"),
          "Part i's last recorded shape as OCCT text BREP (own frame, in its unit; what FreeCAD's "
          "importBrepFromString reads), or None; RuntimeError when the recorded bytes are not a shape, the "
          "checks of a part's load refuse it or its display mesh does not finish (checked in the loader "
          "process: a recording may come from anyone).")
      .def_property_readonly("events",
                             [](const ReviewTrack& r) {
                               py::list out;
                               for (const auto& e : r.events) {
                                 std::string text = e.text;
                                 if (e.from != e.to)
                                   text += (text.empty() ? "" : "; ") + std::string(grasp::toString(e.from)) + " -> " +
                                           grasp::toString(e.to);
                                 out.append(py::make_tuple(e.time_s, text, (e.events & servo::kWatchdogTrip) != 0));
                               }
                               return out;
                             })
      .def_property_readonly(
          "annotations",
          [mmTuple](const ReviewTrack& r) {
            py::list out;
            for (const auto& n : r.notes)
              out.append(py::make_tuple(n.note.time_s, n.note.text, n.note.part, mmTuple(n.hand_m)));
            return out;
          },
          "The reviewers' notes in time order: (time s, text, part or '', the hand's position then in mm: "
          "the midpoint of index and thumb).");
  m.def(
      "open_review",
      [](const std::string& path, double frameRate_hz) {
        py::gil_scoped_release release;
        return std::make_shared<ReviewTrack>(session::readReviewTrack(path, frameRate_hz));
      },
      py::arg("path"), py::arg("frame_rate_hz") = 60.0,
      "Reads a recording for review (one pass; the GIL is released). RuntimeError for a file that is not a "
      "recording; a truncated one opens with what it holds.");

  py::dict events;
  for (int bit = 0; bit < grasp::kEventCount; ++bit)
    events[grasp::eventName(static_cast<grasp::GraspEvent>(1u << bit))] = 1u << bit;
  events["watchdog trip"] = static_cast<std::uint32_t>(servo::kWatchdogTrip);
  events["watchdog clear"] = static_cast<std::uint32_t>(servo::kWatchdogClear);
  m.attr("EVENTS") = events;
}
