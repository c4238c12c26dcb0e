// The pixel-sampling options rad-intervals, rad-compose and rad-reference share, declared once
// with one help text each (ParameterTable, parameter_table.h; pixel_filter.h, sample_grid.h):
// --pixel-filter, --filter-width, --pixel-samples, in the Quality group. Where a stage takes the
// value from elsewhere (rad-compose: intervals.rti's), `unsetMeans` says so in the help.
#pragma once

#include <string>

#include "libcommon/core/parameter_table.h"
#include "libcommon/scene/sample_grid.h"

namespace rad {

namespace detail {
inline std::string defaultNote(const std::string& unsetMeans) {
  return unsetMeans.empty() ? std::string() : " (default: " + unsetMeans + ")";
}
}  // namespace detail

// --pixel-filter none|box|gaussian|blackman-harris and --filter-width W (pixels).
template <class O, class FilterField, class WidthField>
void addPixelFilterParameters(ParameterTable<O>& table, FilterField filter, WidthField width,
                              const std::string& unsetMeans = "") {
  table.addEnum("pixel-filter", filter, pixelFilterNames(),
                "pixel filter, as Blender Cycles': blackman-harris (Blender's default), "
                "gaussian, box, or none (one sample through each pixel centre, unfiltered)" +
                    detail::defaultNote(unsetMeans),
                ParameterGroup::kQuality);
  table.add("filter-width", width,
            "pixel filter width in pixels, as Cycles' Filter Size (blackman-harris: support "
            "+-width; gaussian: sd width/4, support +-1.5 width; box: +-width/2)" +
                detail::defaultNote(unsetMeans),
            ParameterCheck::range(0.01, 16.0), ParameterGroup::kQuality);
}

// --pixel-samples S: an odd S x S grid of samples a pixel (the pixel centre one of them).
template <class O, class F>
void addPixelSamplesParameter(ParameterTable<O>& table, F field,
                              const std::string& unsetMeans = "") {
  table.add("pixel-samples", field,
            "samples a pixel along each axis, odd (S x S on a regular sub-pixel grid, each "
            "pixel's filter weighting its own and its neighbours'); not used with "
            "--pixel-filter none" +
                detail::defaultNote(unsetMeans),
            ParameterCheck::range(1, 15), ParameterGroup::kQuality);
}

}  // namespace rad
