// The options several stages share, declared once with one help text and one check each
// (ParameterTable, parameter_table.h): --frames, --fps, --size, --camera. Where a stage takes
// the default from elsewhere (the scene's animation, the intervals' window), `unsetMeans` says
// so in the help.
#pragma once

#include <string>

#include "libcommon/core/parameter_table.h"

namespace rad {

// --frames FIRST-LAST[xSTEP]; empty: `unsetMeans`.
template <class O, class F>
void addFramesParameter(ParameterTable<O>& table, F field, const std::string& unsetMeans) {
  table.add(
      "frames", field,
      "frames FIRST-LAST or FIRST-LASTxSTEP, frame f at time f / fps (default: " + unsetMeans + ")",
      ParameterCheck::frameRange(), ParameterGroup::kCommon);
}

// --fps F > 0: frame f is at time f / fps.
template <class O, class F>
void addFpsParameter(ParameterTable<O>& table, F field, const std::string& unsetMeans = "") {
  table.add("fps", field,
            "frames per second; frame f is at time f / fps" +
                (unsetMeans.empty() ? std::string() : " (default: " + unsetMeans + ")"),
            ParameterCheck::positive(), ParameterGroup::kCommon);
}

// --size WIDTHxHEIGHT, the final frame's size.
template <class O, class F>
void addSizeParameter(ParameterTable<O>& table, F field, const std::string& unsetMeans = "") {
  table.add("size", field,
            "image size WIDTHxHEIGHT, 1..16384 a side" +
                (unsetMeans.empty() ? std::string() : " (default: " + unsetMeans + ")"),
            ParameterCheck::imageSize(), ParameterGroup::kCommon);
}

// --camera NAME: a camera node or camera name; empty: the scene's first camera.
template <class O, class F>
void addCameraParameter(ParameterTable<O>& table, F field) {
  table.add("camera", field, "camera node or camera name (default: the scene's first camera)",
            ParameterCheck{}, ParameterGroup::kCommon);
}

}  // namespace rad
