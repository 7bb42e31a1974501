# An artifact kind is reached through the registry (issue 33): the layers ask an artifact's kind
# what it does (include/artcal/artifact/artifact_kind.hpp), never which kind it is. The kinds are
# found, not listed: every `.name = "..."` of an ArtifactKind in src/artifact/. Outside the
# kinds' own files, their codecs and the registry, no line of code
#   - compares with a kind's name ("plane" == ...),
#   - reads a kind's name to branch on it (kind().name, artifactTypeName(...) ==).
# Run: cmake -DSOURCE_DIR=... -P tests/artifact/artifact_kinds.cmake
cmake_minimum_required(VERSION 3.20)
file(GLOB kind_files ${SOURCE_DIR}/src/artifact/*.cpp)
set(names "")
foreach(kind_file ${kind_files})
  file(STRINGS ${kind_file} lines REGEX "\\.name = \"[a-z_]+\"")
  foreach(line ${lines})
    string(REGEX REPLACE ".*\\.name = \"([a-z_]+)\".*" "\\1" name "${line}")
    list(APPEND names ${name})
  endforeach()
endforeach()
list(LENGTH names name_count)
if(name_count LESS 6)
  message(FATAL_ERROR "artifact_kinds.cmake found ${name_count} kinds (${names}): update its "
                      "pattern")
endif()
list(JOIN names "|" name_pattern)

file(GLOB_RECURSE files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/src/*.cpp ${SOURCE_DIR}/src/*.hpp
     ${SOURCE_DIR}/include/*.hpp ${SOURCE_DIR}/tools/*.cpp ${SOURCE_DIR}/tools/*.hpp
     ${SOURCE_DIR}/python/*.cpp)
set(allowed "^(src/artifact/|include/artcal/artifact/|src/io/[a-z0-9_]+_codec\\.cpp$|include/artcal/io/[a-z0-9_]+_codec\\.hpp$|src/io/artifact_registry\\.cpp$|include/artcal/io/artifact_registry\\.hpp$)")
set(faults "")
foreach(file ${files})
  if(file MATCHES "${allowed}")
    continue()
  endif()
  file(STRINGS ${SOURCE_DIR}/${file} lines)
  set(number 0)
  foreach(line IN LISTS lines)
    math(EXPR number "${number} + 1")
    string(REGEX REPLACE "//.*" "" code " ${line} ")
    if(code MATCHES "[=!]= *\"(${name_pattern})\"")
      string(APPEND faults "  ${file}:${number} compares with the kind name \"${CMAKE_MATCH_1}\"\n")
    elseif(code MATCHES "\"(${name_pattern})\" *[=!]=")
      string(APPEND faults "  ${file}:${number} compares with the kind name \"${CMAKE_MATCH_1}\"\n")
    endif()
    if(code MATCHES "kind\\(\\)\\.name" OR code MATCHES "artifactTypeName\\([^)]*\\) *[=!]="
       OR code MATCHES "[=!]= *artifactTypeName")
      string(APPEND faults "  ${file}:${number} branches on an artifact's kind name\n")
    endif()
  endforeach()
endforeach()
if(faults)
  message(FATAL_ERROR "an artifact kind is asked what it does (artifact/artifact_kind.hpp), "
                      "never which it is:\n${faults}")
endif()
message(STATUS "artifact kinds ${names}: named only in their files, codecs and the registry\n")
