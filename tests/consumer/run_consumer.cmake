# The test Install.ConsumerFindPackage (issue 20 point 3): installs the build tree, builds
# tests/consumer against the installed package with find_package(artcal) and checks that the
# consumer's u of l1 for plans/paper-2r-5bars.json is the one `artcal evaluate --json` prints.
# Variables: BUILD_DIR, WORK_DIR, CONSUMER_DIR, PLAN, CLI, CXX_COMPILER, BUILD_TYPE, GENERATOR.
cmake_minimum_required(VERSION 3.20)
set(prefix ${WORK_DIR}/prefix)
set(consumer_build ${WORK_DIR}/build)
file(REMOVE_RECURSE ${prefix})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${what} failed (${status}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

run("cmake --install" ${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
foreach(expected include/artcal/artcal.hpp bin/artcal lib/cmake/artcal/artcalConfig.cmake)
  if(NOT EXISTS ${prefix}/${expected})
    message(FATAL_ERROR "the installed tree lacks ${expected}")
  endif()
endforeach()
# Internal headers stay out of the installed tree.
foreach(internal artcal/internal.hpp artcal/report/html_report.hpp artcal/io/model_registry.hpp)
  if(EXISTS ${prefix}/include/${internal})
    message(FATAL_ERROR "the internal header ${internal} was installed")
  endif()
endforeach()

# The installed headers include no JSON header (the umbrella's promise, artcal/artcal.hpp).
file(GLOB_RECURSE installed_headers ${prefix}/include/artcal/*.hpp)
foreach(header ${installed_headers})
  file(STRINGS ${header} json_includes REGEX "^#include <nlohmann/")
  if(json_includes)
    message(FATAL_ERROR "the installed header ${header} includes ${json_includes}")
  endif()
endforeach()

run("configuring the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${consumer_build}
    -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run("building the consumer" ${CMAKE_COMMAND} --build ${consumer_build})
run("running the consumer" ${consumer_build}/artcal_consumer ${PLAN})
set(consumer_output "${output}")
message(STATUS "consumer:\n${consumer_output}")

run("artcal evaluate --json" ${CLI} evaluate ${PLAN} --json)
string(JSON name GET "${output}" parameters 0 name)
string(JSON expected GET "${output}" parameters 0 u)
string(JSON unit GET "${output}" parameters 0 unit)
if(NOT name STREQUAL "l1")
  message(FATAL_ERROR "evaluate --json: parameters/0 is ${name}, not l1")
endif()
string(REGEX MATCH "(^|\n)l1 ([^ ]+) ([a-z]+)" matched "${consumer_output}")
if(NOT matched)
  message(FATAL_ERROR "the consumer printed no line for l1")
endif()
set(consumer_u ${CMAKE_MATCH_2})
set(consumer_unit ${CMAKE_MATCH_3})
# Both are the same double printed to 17 significant digits (string(JSON) and %.17g).
if(NOT consumer_u STREQUAL expected OR NOT consumer_unit STREQUAL unit)
  message(FATAL_ERROR "u(l1): consumer ${consumer_u} ${consumer_unit}, evaluate --json ${expected} ${unit}")
endif()
message(STATUS "u(l1) = ${consumer_u} ${consumer_unit} from both")
