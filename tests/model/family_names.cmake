# A family is reached through the registry (issue 20 point 2): no code outside the model layer
# and the registry names a mechanism family. The families are found, not listed: every
# `class NAME final : public ...Mechanism` of include/artcal/model/ with its header and the name
# its modelName() returns. Outside the allowed files below no line of code
#   - includes a family's header (artcal/model/<family>.hpp),
#   - names a family's class (a dynamic_cast, a static_cast, a member),
#   - compares with a family's name in files ("cartesian" == ...),
#   - asks a model for a type by dynamic_cast (a capability is a virtual of Mechanism).
# A family's extras reach the rest through Mechanism's capabilities (orientedPostures(),
# axisErrorFunctions(), stylusCount(), ...). Allowed: src/model/ and include/artcal/model/, the
# registry and the codecs (src/io/model_registry.cpp, src/io/*_codec.cpp and their headers), the
# chain's other exchange format (io/urdf, the URDF module src/urdf/, io/calibrated_urdf) and the
# public umbrella artcal.hpp.
# Run: cmake -DSOURCE_DIR=... -P tests/model/family_names.cmake
cmake_minimum_required(VERSION 3.20)
set(word "[^A-Za-z0-9_]")
file(GLOB model_headers ${SOURCE_DIR}/include/artcal/model/*.hpp)
set(classes "")
set(headers "")
set(names "")
include(${CMAKE_CURRENT_LIST_DIR}/../support/code_lines.cmake)
foreach(header ${model_headers})
  set(families "")
  artcal_captured(${header} "^class ([A-Za-z0-9_]+) final : public .*Mechanism" families)
  if(NOT families)
    continue()
  endif()
  list(APPEND classes ${families})
  get_filename_component(stem ${header} NAME_WE)
  list(APPEND headers ${stem})
  artcal_captured(${header} "modelName\\(\\) const override { return \"([^\"]+)\"" names)
endforeach()
list(LENGTH classes class_count)
list(LENGTH names name_count)
if(class_count LESS 5 OR NOT class_count EQUAL name_count)
  message(FATAL_ERROR "family_names.cmake found ${class_count} families (${classes}) and "
                      "${name_count} model names (${names}): update its patterns")
endif()

list(JOIN headers "|" header_pattern)
list(JOIN classes "|" class_pattern)
list(JOIN names "|" name_pattern)

set(allowed "^(src/model/|include/artcal/model/|src/io/model_registry\\.cpp$|src/io/[a-z0-9_]+_codec\\.cpp$|include/artcal/io/[a-z0-9_]+_codec\\.hpp$|include/artcal/io/model_registry\\.hpp$|src/io/urdf\\.cpp$|src/urdf/|include/artcal/io/urdf\\.hpp$|src/io/calibrated_urdf\\.cpp$|include/artcal/io/calibrated_urdf\\.hpp$|include/artcal/artcal\\.hpp$)")
# Code only: no comment (a family may be named in prose).
function(check_line file number code)
  string(REGEX REPLACE "\"[^\"]*\"" "\"\"" code_outside_strings "${code}")
  if(code MATCHES "#include \"artcal/model/(${header_pattern})\\.hpp\"")
    string(APPEND faults "  ${file}:${number} includes artcal/model/${CMAKE_MATCH_1}.hpp\n")
  endif()
  if(code_outside_strings MATCHES "${word}(${class_pattern})${word}")
    string(APPEND faults "  ${file}:${number} names the class ${CMAKE_MATCH_1}\n")
  endif()
  if(code_outside_strings MATCHES "dynamic_cast *<")
    string(APPEND faults "  ${file}:${number} casts a model (ask Mechanism for a capability)\n")
  endif()
  artcal_compared_name("${code}" "${name_pattern}" compared)
  if(compared)
    string(APPEND faults "  ${file}:${number} compares with the model name \"${compared}\"\n")
  endif()
  set(faults "${faults}" PARENT_SCOPE)
endfunction()
artcal_check_code_lines("${allowed}" check_line)
if(faults)
  message(FATAL_ERROR "a family is reached through the registry and Mechanism's capabilities "
                      "(include/artcal/io/model_registry.hpp), never by its name:\n${faults}")
endif()
message(STATUS "families ${classes} (${names}): named only in the model layer and the registry\n")
