# report/ as a view (issue 20 point 1): the report files may include from estimation/ and
# planning/ only the headers listed here. Each pair is a FILE|HEADER the report reads today (the
# typed results it draws, and the computing headers it still calls: design_matrix.hpp and tip.hpp
# for the workspace map and the procedure's placements, error_functions.hpp for the CMM's
# answers), to be removed as report/ becomes a pure view; a new include fails this test.
# Run: cmake -DSOURCE_DIR=... -P tests/report/report_includes.cmake
cmake_minimum_required(VERSION 3.20)
set(allowed
    "src/report/html_report.cpp|artcal/estimation/design_matrix.hpp"
    "src/report/html_report.cpp|artcal/estimation/tip.hpp"
    "src/report/procedure.cpp|artcal/estimation/design_matrix.hpp"
    "include/artcal/report/cartesian_report.hpp|artcal/estimation/error_functions.hpp"
    "include/artcal/report/cartesian_report.hpp|artcal/estimation/evaluator.hpp"
    "include/artcal/report/html_report.hpp|artcal/estimation/evaluator.hpp"
    "include/artcal/report/report.hpp|artcal/estimation/evaluator.hpp"
    "include/artcal/report/report.hpp|artcal/estimation/identifiability.hpp"
    "include/artcal/report/sweep_report.hpp|artcal/planning/placement_sweep.hpp")
file(GLOB report_files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/src/report/*.cpp
     ${SOURCE_DIR}/src/report/*.hpp ${SOURCE_DIR}/include/artcal/report/*.hpp)
set(faults "")
foreach(file ${report_files})
  file(STRINGS ${SOURCE_DIR}/${file} lines REGEX "^#include \"artcal/(estimation|planning)/")
  foreach(line ${lines})
    string(REGEX REPLACE "^#include \"([^\"]+)\".*" "\\1" header "${line}")
    if(NOT "${file}|${header}" IN_LIST allowed)
      string(APPEND faults "  ${file} includes ${header}\n")
    endif()
  endforeach()
endforeach()
if(faults)
  message(FATAL_ERROR "report/ is a view over typed results; new includes of estimation/ or "
                      "planning/ headers:\n${faults}Compute in estimation/planning and pass the "
                      "result (tests/report/report_includes.cmake lists the known ones).")
endif()
