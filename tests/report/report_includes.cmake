# report/ as a view (issue 20 point 1): the report files may include from estimation/ and
# planning/ only the result-type headers listed here, and those include from estimation/ and
# planning/ only each other. What remains are plain types, computed once in estimation/ and
# planning/ and carried to the report:
#   evaluation_result.hpp      the Evaluation (identifiability, V_p, tip summary, S per workspace
#                              configuration, the placed features), from evaluatePlan
#   identifiability_result.hpp its identifiability (counting condition, rank, combinations)
#   cartesian_answers.hpp      the answers and error-function bands of a model with axis error
#                              functions (a Cartesian CMM), from cartesianAnswers /
#                              errorFunctionBands (error_functions.hpp)
#   procedure_result.hpp       the operator's procedure (poses, inverse kinematics), from
#                              operatorProcedure (planning/procedure.hpp)
#   placement_sweep_result.hpp the placement sweep, from sweepPlacements
# No .cpp of report/ includes an estimation/ or planning/ header, nor do the acceptance/ headers
# the report reads its predictions from (the acceptance layer's computation, evaluatePlan among
# it, is in its .cpp files); a new include fails this test.
# Run: cmake -DSOURCE_DIR=... -P tests/report/report_includes.cmake
cmake_minimum_required(VERSION 3.20)
set(result_headers
    artcal/estimation/evaluation_result.hpp artcal/estimation/identifiability_result.hpp
    artcal/estimation/cartesian_answers.hpp artcal/planning/procedure_result.hpp
    artcal/planning/placement_sweep_result.hpp)
set(allowed
    "include/artcal/acceptance/acceptance.hpp|artcal/estimation/evaluation_result.hpp"
    "include/artcal/acceptance/plan_acceptance.hpp|artcal/estimation/evaluation_result.hpp"
    "include/artcal/report/cartesian_report.hpp|artcal/estimation/cartesian_answers.hpp"
    "include/artcal/report/html_report.hpp|artcal/estimation/evaluation_result.hpp"
    "include/artcal/report/location_errors.hpp|artcal/estimation/evaluation_result.hpp"
    "include/artcal/report/html_report.hpp|artcal/planning/procedure_result.hpp"
    "include/artcal/report/procedure.hpp|artcal/planning/procedure_result.hpp"
    "include/artcal/report/report.hpp|artcal/estimation/cartesian_answers.hpp"
    "include/artcal/report/report.hpp|artcal/estimation/evaluation_result.hpp"
    "include/artcal/report/sweep_report.hpp|artcal/planning/placement_sweep_result.hpp")
foreach(header ${result_headers})
  list(APPEND allowed "include/${header}|artcal/estimation/identifiability_result.hpp")
endforeach()
file(GLOB report_files RELATIVE ${SOURCE_DIR} ${SOURCE_DIR}/src/report/*.cpp
     ${SOURCE_DIR}/src/report/*.hpp ${SOURCE_DIR}/include/artcal/report/*.hpp
     ${SOURCE_DIR}/include/artcal/acceptance/*.hpp)
foreach(header ${result_headers})
  list(APPEND report_files include/${header})
endforeach()
set(faults "")
foreach(file ${report_files})
  if(NOT EXISTS ${SOURCE_DIR}/${file})
    string(APPEND faults "  ${file} is missing\n")
    continue()
  endif()
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
                      "result (tests/report/report_includes.cmake lists the result headers).")
endif()
