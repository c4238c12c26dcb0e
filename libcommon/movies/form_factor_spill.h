// Where the texture-movie bake parks a moving pair's per-key form factors between the scan
// that finds their maximum (which fixes the pair's sample count, paper §3.1 step 1) and the
// key that uses them (texture_movie_baker.h, "Memory").
//
// libcommon does no file I/O: the store is an interface. rad-movies passes the scratch-file
// implementation (formats/form_factor_scratch_file.h: an unlinked temporary file the page
// cache holds, not the process); without one (NoFormFactorSpill) every set is recomputed when
// its key is baked. Either way the values are the same, bit for bit: a store that fails only
// costs the recomputation.
#pragma once

#include <functional>
#include <memory>
#include <vector>

namespace rad {

class FormFactorSpill {
 public:
  virtual ~FormFactorSpill() = default;
  // Stores a set of form factors; returns where (>= 0), or -1 when it could not be stored.
  virtual long long put(const std::vector<double>& f) = 0;
  // Reads the set stored at `at` into f (f.size() values, f already sized); false when it
  // cannot (at < 0, a read failure): the caller then recomputes it.
  virtual bool get(long long at, std::vector<double>& f) const = 0;
};

// Stores nothing: put() gives -1, so every set is recomputed.
class NoFormFactorSpill final : public FormFactorSpill {
 public:
  long long put(const std::vector<double>&) override { return -1; }
  bool get(long long, std::vector<double>&) const override { return false; }
};

// One store per movie: called at the start of each bake() and dropped at its end.
using FormFactorSpillFactory = std::function<std::unique_ptr<FormFactorSpill>()>;

}  // namespace rad
