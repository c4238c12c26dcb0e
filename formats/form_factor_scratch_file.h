// The scratch file behind libcommon's FormFactorSpill (libcommon/movies/form_factor_spill.h):
// rad-movies parks a moving pair's per-key form factors in an unlinked temporary file
// (std::tmpfile) and reads them back when their key is baked, so the page cache holds them
// (the kernel writes them out under memory pressure), not the process, and reading them back
// costs far less than recomputing. Layout: the sets one after another as native doubles, no
// header; the file lives only as long as the movie's bake and is never seen by a user.
//
// Any failure (no temporary directory, a full disk, a short read) only means the baker
// recomputes the set: same values, bit for bit.
#pragma once

#include <cstdio>
#include <vector>

#include "libcommon/movies/form_factor_spill.h"

namespace rad {

class FormFactorScratchFile final : public FormFactorSpill {
 public:
  FormFactorScratchFile() = default;  // the file is created on the first put()
  ~FormFactorScratchFile() override;
  FormFactorScratchFile(const FormFactorScratchFile&) = delete;
  FormFactorScratchFile& operator=(const FormFactorScratchFile&) = delete;

  long long put(const std::vector<double>& f) override;
  bool get(long long at, std::vector<double>& f) const override;

 private:
  std::FILE* file_ = nullptr;
  long long size_ = 0;
  bool failed_ = false;
};

// A factory for TextureMovieBakerBackends::formFactorSpill: one scratch file per movie.
FormFactorSpillFactory formFactorScratchFiles();

}  // namespace rad
