# An artifact kind is reached through the registry (issue 33): the layers ask an artifact's kind
# what it does (include/artcal/artifact/artifact_kind.hpp), never which kind it is. The kinds are
# found, not listed: every `.name = "..."` of an ArtifactKind in src/artifact/. Outside the
# kinds' own files, their codecs and the registry, no line of code
#   - compares with a kind's name ("plane" == ...),
#   - reads a kind's name to branch on it (kind().name, artifactTypeName(...) ==).
# Run: cmake -DSOURCE_DIR=... -P tests/artifact/artifact_kinds.cmake
cmake_minimum_required(VERSION 3.20)
include(${CMAKE_CURRENT_LIST_DIR}/../support/code_lines.cmake)
file(GLOB kind_files ${SOURCE_DIR}/src/artifact/*.cpp)
set(names "")
foreach(kind_file ${kind_files})
  artcal_captured(${kind_file} "\\.name = \"([a-z_]+)\"" names)
endforeach()
list(LENGTH names name_count)
if(name_count LESS 6)
  message(FATAL_ERROR "artifact_kinds.cmake found ${name_count} kinds (${names}): update its "
                      "pattern")
endif()
list(JOIN names "|" name_pattern)

set(allowed "^(src/artifact/|include/artcal/artifact/|src/io/[a-z0-9_]+_codec\\.cpp$|include/artcal/io/[a-z0-9_]+_codec\\.hpp$|src/io/artifact_registry\\.cpp$|include/artcal/io/artifact_registry\\.hpp$)")
function(check_line file number code)
  artcal_compared_name("${code}" "${name_pattern}" compared)
  if(compared)
    string(APPEND faults "  ${file}:${number} compares with the kind name \"${compared}\"\n")
  endif()
  if(code MATCHES "kind\\(\\)\\.name" OR code MATCHES "artifactTypeName\\([^)]*\\) *[=!]="
     OR code MATCHES "[=!]= *artifactTypeName")
    string(APPEND faults "  ${file}:${number} branches on an artifact's kind name\n")
  endif()
  set(faults "${faults}" PARENT_SCOPE)
endfunction()
artcal_check_code_lines("${allowed}" check_line)
if(faults)
  message(FATAL_ERROR "an artifact kind is asked what it does (artifact/artifact_kind.hpp), "
                      "never which it is:\n${faults}")
endif()
message(STATUS "artifact kinds ${names}: named only in their files, codecs and the registry\n")
