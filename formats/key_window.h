// Key window files (container kind "keywindow"): one time window of rad-global's key-time pass,
// written by `rad-global --window` and merged by `rad-global --merge` into the whole run's
// global.rlh (issue 17, the render farm). Arrays and metadata: formats/key_window.md.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "formats/container.h"
#include "libcommon/radiosity/key_window.h"
#include "libcommon/scene/scene.h"

namespace rad {

constexpr const char* kKeyWindowKind = "keywindow";
constexpr int kKeyWindowMajor = 1;
constexpr int kKeyWindowMinor = 0;

// Writes `window` atomically. `metadata` (an object: parameters, first_frame, last_frame,
// window, run_key_count, coherence) is stored as the kind's metadata; the writer adds
// key_count, node_count, link_count, top_count, first_key and key_reports.
void writeKeyWindow(const std::string& path, const KeyWindow& window, const Provenance& provenance,
                    const nlohmann::json& metadata);

// Reads and validates a keywindow container against the scene it was computed for (the
// top-level patches are the scene's; node ids in subdivision order; every size, index and
// value KeyWindow::validate checks). Errors are one-line rad::inputError(path, ...).
KeyWindow readKeyWindow(const ContainerReader& reader, const Scene& scene);

// Throws rad::inputError(path, ...) unless the window was made by the run this merge stands
// for: the same parameters (`parameters`, GlobalOptions::toJson: "built with --eps 0.02; this
// run expects 0.01") from the scene whose hash is `sceneHash`.
void requireSameRun(const ContainerReader& reader, const nlohmann::json& parameters,
                    const std::string& sceneHash);

// rad-global --merge's inputs: each file opened, checked against the run (requireSameRun) and
// read, in the order given.
std::vector<KeyWindow> readKeyWindows(const std::vector<std::string>& paths, const Scene& scene,
                                      const nlohmann::json& parameters,
                                      const std::string& sceneHash);

// rad-inspect's content summary of a keywindow container (no scene needed).
nlohmann::json summarizeKeyWindow(const ContainerReader& reader);

}  // namespace rad
