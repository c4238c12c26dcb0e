// What build made this binary, for provenance and --version (docs/conventions.md §1 "Files that say
// what made them"). The revision is read when the binary is built, not when CMake is configured:
// the generated build_info.cpp is rewritten by formats/build_info.cmake on every build, and only
// when the revision changed, so an unchanged checkout rebuilds nothing.
#pragma once

namespace rad {

// `git rev-parse --short=12 HEAD` of the source tree when this binary was built, e.g.
// "1a2b3c4d5e6f", with "-dirty" appended when tracked files differed from HEAD (as
// `git describe --dirty`); "unknown" when the sources were not a git checkout (or git was
// missing).
const char* gitRevision();

}  // namespace rad
