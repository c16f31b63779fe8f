#include "part_loader.hpp"

#include <unistd.h>

#include <algorithm>
#include <memory>
#include <mutex>

#include "freecad_boundary.hpp"
#include "hapticgrasp/geometry/geometry_error.hpp"
#include "hapticgrasp/geometry/loader_process.hpp"
#include "hapticgrasp/install_layout.hpp"

namespace hg::freecad {
namespace {

struct Current {
  std::mutex mutex;
  bool chosen = false;  // the default is looked for at the first load
  std::shared_ptr<geometry::LoaderProcess> loader;  // shared: a load keeps its loader while another replaces it
  std::string program, why;
};

Current& current() {
  static Current c;
  return c;
}

// The installed or built program, when it is there to run.
void chooseDefault(Current& c) {
  c.chosen = true;
  c.program = loaderProgram().string();
  if (access(c.program.c_str(), X_OK) != 0) {
    c.why = "no loader program at " + c.program;
    return;
  }
  c.loader = std::make_shared<geometry::LoaderProcess>(geometry::LoaderProcess::Options{{c.program}});
}

std::shared_ptr<geometry::LoaderProcess> loader() {
  Current& c = current();
  std::lock_guard lock(c.mutex);
  if (!c.chosen) chooseDefault(c);
  return c.loader;
}

}  // namespace

geometry::PartModelPtr loadPartText(std::string_view brep, const std::string& name,
                                    const geometry::PartModel::LoadOptions& options,
                                    const std::atomic<bool>* cancelled) {
  if (const auto l = loader()) return l->load(brep, kDocumentUnit, name, options, cancelled);
  return geometry::PartModel::fromBrepText(brep, kDocumentUnit, name, options);
}

geometry::ModelCache::Build cacheBuild(std::shared_ptr<const std::atomic<bool>> cancelled) {
  const auto l = loader();
  if (!l) return {};
  return [l, cancelled](std::string_view brep, geometry::LengthUnit unit, const std::string& name,
                        const geometry::PartModel::LoadOptions& options) {
    return l->load(brep, unit, name, options, cancelled.get());
  };
}

std::string recordedShapeText(const session::RecordedPart& part) {
  const auto l = loader();
  if (!l) return session::brepAsText(part);
  try {
    return l->displayableText(part.brep, part.unit, part.name);
  } catch (const geometry::GeometryError& e) {
    const std::string why = e.what();
    // The check's own verdict completes "its recorded shape ..."; the helper's end is a sentence.
    const bool verdict = why.rfind("is ", 0) == 0 || why.rfind("cannot be shown", 0) == 0;
    throw session::SessionError("part '" + part.name + "': its recorded shape " + (verdict ? "" : "could not be checked: ") +
                                why);
  }
}

LoaderStatus loaderStatus() {
  const auto l = loader();
  Current& c = current();
  std::lock_guard lock(c.mutex);
  LoaderStatus s;
  s.isolated = l != nullptr;
  s.program = l ? l->options().command.front() : c.program;
  s.started = l ? l->started() : 0;
  s.timeLimit_s = l ? l->options().limits.time.count() / 1e3 : 0;
  s.why = c.why;
  return s;
}

void useLoader(std::vector<std::string> command, double timeLimit_s) {
  if (!(timeLimit_s > 0)) throw std::invalid_argument("the loader's time limit must be positive");
  if (command.empty()) {  // the installed or built one, looked for again at the next load
    Current& c = current();
    std::lock_guard lock(c.mutex);
    c.chosen = false;
    c.loader.reset();
    c.why.clear();
    return;
  }
  geometry::LoaderProcess::Options options;
  options.command = std::move(command);
  options.limits.time = std::chrono::milliseconds(static_cast<long long>(std::min(timeLimit_s, 1e6) * 1e3));
  auto next = std::make_shared<geometry::LoaderProcess>(std::move(options));  // throws for no program
  Current& c = current();
  std::lock_guard lock(c.mutex);
  c.chosen = true;
  c.program = next->options().command.front();
  c.why.clear();
  c.loader = std::move(next);
}

void useNoLoader(const std::string& why) {
  Current& c = current();
  std::lock_guard lock(c.mutex);
  c.chosen = true;
  c.loader.reset();
  c.why = why;
}

}  // namespace hg::freecad
