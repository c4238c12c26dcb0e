# Writes the one source of the radbuildinfo library (formats/build_info.h): the git revision of
# SOURCE_DIR, read at build time. Run by the rad_build_info target (top-level CMakeLists.txt) as
#   cmake -DSOURCE_DIR=... -DGIT=... -DOUTPUT=.../build_info.cpp -P formats/build_info.cmake
# OUTPUT is rewritten only when its content changes, so an unchanged revision recompiles nothing.
set(revision "unknown")
if(GIT)
  execute_process(COMMAND "${GIT}" rev-parse --show-toplevel --short=12 HEAD
                  WORKING_DIRECTORY "${SOURCE_DIR}"
                  RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_QUIET
                  OUTPUT_STRIP_TRAILING_WHITESPACE)
  if(status EQUAL 0)
    string(REPLACE "\n" ";" lines "${out}")
    list(LENGTH lines count)
    if(count EQUAL 2)
      list(GET lines 0 top)
      list(GET lines 1 head)
      # Only this tree's own checkout counts, not a repository the sources were unpacked into.
      file(REAL_PATH "${top}" top)
      file(REAL_PATH "${SOURCE_DIR}" source)
      if(top STREQUAL source)
        set(revision "${head}")
        # Tracked files that differ from HEAD (staged or not): the binary is not that revision's,
        # and says so as git describe --dirty does. (A benchmark binary built before its commit had
        # carried the parent's revision.)
        execute_process(COMMAND "${GIT}" diff --quiet HEAD --
                        WORKING_DIRECTORY "${SOURCE_DIR}" RESULT_VARIABLE dirty ERROR_QUIET)
        if(dirty EQUAL 1)
          set(revision "${head}-dirty")
        endif()
      endif()
    endif()
  endif()
endif()

set(content "// Generated at build time by formats/build_info.cmake; do not edit.
#include \"formats/build_info.h\"

namespace rad {

const char* gitRevision() { return \"${revision}\"; }

}  // namespace rad
")
set(old "")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" old)
endif()
if(NOT old STREQUAL content)
  file(WRITE "${OUTPUT}" "${content}")
endif()
