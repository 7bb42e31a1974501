# The test Package.DebInstallsAndBuildsAConsumer (issue 33): `cpack -G DEB` of the build tree,
# the .deb unpacked with `dpkg -x` into a scratch root (no root needed), its contents checked
# (the program, the umbrella header, the CMake config, the Python module when built), then
# tests/consumer configured against the unpacked /usr with find_package(artcal), built and run on
# PLAN: it must print the u of l1 that the unpacked program's `evaluate --json` prints.
# The package also installed with `dpkg -i` into a scratch root of its own: its program imports
# URDF (a UR5 to its ball), run by its full path and by its name through PATH, which loads the
# packaged URDF module (src/urdf/urdf_module.hpp) from that root, not the build tree's.
# Variables: BUILD_DIR, WORK_DIR, CONSUMER_DIR, PLAN, URDF, CXX_COMPILER, BUILD_TYPE, GENERATOR, PYTHON
# (empty without the module).
cmake_minimum_required(VERSION 3.20)
set(root ${WORK_DIR}/root)
file(REMOVE_RECURSE ${WORK_DIR})
file(MAKE_DIRECTORY ${WORK_DIR})

function(run what)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "${what} failed (${status}):\n${out}\n${err}")
  endif()
  set(output "${out}" PARENT_SCOPE)
endfunction()

run("cpack -G DEB" ${CMAKE_COMMAND} -E chdir ${BUILD_DIR} cpack -G DEB -B ${WORK_DIR}/deb)
file(GLOB debs ${WORK_DIR}/deb/artcal_*.deb)
list(LENGTH debs count)
if(NOT count EQUAL 1)
  message(FATAL_ERROR "expected one artcal_*.deb in ${WORK_DIR}/deb, found: ${debs}")
endif()
run("dpkg-deb --field" dpkg-deb --field ${debs} Package Depends)
message(STATUS "${output}")
string(FIND "${output}" "libeigen3-dev" eigen)
if(eigen LESS 0)
  message(FATAL_ERROR "the package does not depend on libeigen3-dev:\n${output}")
endif()
run("dpkg -x" dpkg -x ${debs} ${root})
foreach(expected usr/bin/artcal usr/include/artcal/artcal.hpp usr/lib/cmake/artcal/artcalConfig.cmake)
  if(NOT EXISTS ${root}/${expected})
    message(FATAL_ERROR "the package lacks /${expected}")
  endif()
endforeach()
if(EXISTS ${root}/usr/include/artcal/internal.hpp)
  message(FATAL_ERROR "the package installs the internal header artcal/internal.hpp")
endif()

file(GLOB_RECURSE urdf_modules ${root}/usr/*/libartcal_urdf.so)
if(NOT urdf_modules MATCHES "/usr/lib[^;]*/artcal/libartcal_urdf[.]so")
  message(FATAL_ERROR "the package lacks the URDF module in /usr/lib.../artcal/: ${urdf_modules}")
endif()
# The package installed with `dpkg -i` into a scratch root of its own (--root: its own dpkg
# database, so the host's installed packages are not changed; --force-depends: that database
# does not list the dependencies, the host has them). Its program by its full path, then by its
# name through PATH (as a user runs it, issue 44) from a folder of its own: both load the
# packaged module, found from the program's real path (<root>/usr/bin/artcal ->
# <root>/usr/lib/artcal), not from the current folder nor from the configured install prefix
# (/usr/local).
set(installed ${WORK_DIR}/installed)
file(MAKE_DIRECTORY ${installed}/var/lib/dpkg/info ${installed}/var/lib/dpkg/updates
     ${installed}/var/lib/dpkg/triggers)
file(TOUCH ${installed}/var/lib/dpkg/status ${installed}/var/lib/dpkg/available)
run("dpkg -i" dpkg --root=${installed} --force-depends --force-not-root --force-script-chrootless
    -i ${debs})
find_program(ARTCAL_ENV env REQUIRED)
file(GLOB_RECURSE urdf_modules ${installed}/usr/*/libartcal_urdf.so)
list(GET urdf_modules 0 urdf_module)
file(MAKE_DIRECTORY ${WORK_DIR}/elsewhere)
foreach(how "full path" "name through PATH")
  if(how STREQUAL "name through PATH")
    set(program artcal)
  else()
    set(program ${installed}/usr/bin/artcal)
  endif()
  execute_process(
    COMMAND ${ARTCAL_ENV} -u ARTCAL_URDF_MODULE PATH=${installed}/usr/bin:/usr/bin:/bin LD_DEBUG=files
            ${program} import-urdf ${URDF} --base base_link --tip ball_link
    WORKING_DIRECTORY ${WORK_DIR}/elsewhere
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  string(FIND "${err}" "file=${urdf_module}" loaded)
  if(NOT status EQUAL 0 OR NOT out MATCHES "\"model\": \"chain\"" OR loaded LESS 0)
    message(FATAL_ERROR "the packaged import-urdf run by its ${how} (${status}) did not import "
                        "through the packaged module:\n${out}\n${err}")
  endif()
  message(STATUS "import-urdf run by its ${how} loaded the packaged ${urdf_module}")
endforeach()

run("the packaged artcal evaluate --json" ${root}/usr/bin/artcal evaluate ${PLAN} --json)
string(JSON expected GET "${output}" parameters 0 u)

run("configuring the consumer" ${CMAKE_COMMAND} -S ${CONSUMER_DIR} -B ${WORK_DIR}/consumer
    -G ${GENERATOR} -DCMAKE_BUILD_TYPE=${BUILD_TYPE} -DCMAKE_CXX_COMPILER=${CXX_COMPILER}
    -DCMAKE_PREFIX_PATH=${root}/usr -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF)
run("building the consumer" ${CMAKE_COMMAND} --build ${WORK_DIR}/consumer)
run("running the consumer" ${WORK_DIR}/consumer/artcal_consumer ${PLAN})
string(REGEX MATCH "(^|\n)l1 ([^ ]+) " matched "${output}")
if(NOT matched OR NOT CMAKE_MATCH_2 STREQUAL expected)
  message(FATAL_ERROR "u(l1): consumer '${CMAKE_MATCH_2}', packaged evaluate --json ${expected}")
endif()
message(STATUS "u(l1) = ${expected} from the packaged program and the consumer")

if(PYTHON)
  file(GLOB_RECURSE modules ${root}/usr/lib/__init__.py)
  list(FILTER modules INCLUDE REGEX "/usr/lib/python3/dist-packages/artcal/__init__[.]py$")
  if(NOT modules)
    message(FATAL_ERROR "the package lacks the Python module")
  endif()
  list(GET modules 0 module)
  get_filename_component(package_dir ${module} DIRECTORY)
  get_filename_component(site ${package_dir} DIRECTORY)
  execute_process(
    COMMAND ${CMAKE_COMMAND} -E env PYTHONPATH=${site} PYTHONDONTWRITEBYTECODE=1 ${PYTHON} -c
            "import artcal; print(repr(artcal.Plan(r'${PLAN}').evaluate().u[0]))"
    RESULT_VARIABLE status OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT status EQUAL 0)
    message(FATAL_ERROR "the packaged Python module failed:\n${out}\n${err}")
  endif()
  message(STATUS "the packaged Python module: u(l1) = ${out}")
endif()
