#pragma once
// Where the workbench loads its parts: in the loader process (core geometry/loader_process.hpp),
// so that a shape that crashes OpenCASCADE, sends it into a loop or eats memory costs that
// process, never FreeCAD and the user's unsaved work; the part keeps its stand-in box and
// the error names it. Without the loader's program (a broken install) parts load in
// FreeCAD's own process, as loaderStatus() says and the workbench reports once.
#include <atomic>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "hapticgrasp/geometry/model_cache.hpp"
#include "hapticgrasp/geometry/part_model.hpp"
#include "hapticgrasp/session/session_description.hpp"

namespace hg::freecad {

struct LoaderStatus {
  bool isolated = false;     // parts load in the loader process
  std::string program;       // its program (or the one looked for)
  std::size_t started = 0;   // helper processes started so far
  double timeLimit_s = 0;    // per part
  std::string why;           // !isolated: why not
};

// The part BREP text describes (mm, Placement reset), checked; throws GeometryError. Once
// `cancelled` is set, a load in the loader process ends at once (its helper killed).
geometry::PartModelPtr loadPartText(std::string_view brep, const std::string& name,
                                    const geometry::PartModel::LoadOptions& options,
                                    const std::atomic<bool>* cancelled = nullptr);
// For ModelCache::load: a part the cache lacks is loaded as loadPartText loads it.
geometry::ModelCache::Build cacheBuild(std::shared_ptr<const std::atomic<bool>> cancelled = {});
// A recording's shape as text the Review panel may hand to FreeCAD (core
// geometry/display_shape.hpp): checked, and meshed as FreeCAD's display will mesh it, in the
// loader process; without one, checked here only (meshing here would hang FreeCAD as its
// display would). Throws SessionError naming the part.
std::string recordedShapeText(const session::RecordedPart& part);
LoaderStatus loaderStatus();
// Another helper program and time limit (tests: a stand-in that crashes); an empty command:
// the installed one again. The previous helpers end once their loads do.
void useLoader(std::vector<std::string> command, double timeLimit_s);
// Parts load in FreeCAD's process from now on; loaderStatus().why says `why`.
void useNoLoader(const std::string& why);

}  // namespace hg::freecad
