# Installation and the exported package (issue 20 point 3):
#   cmake --install build --prefix P
# installs the layer libraries, the public headers (include/artcal/artcal.hpp and every artcal
# header it reaches, nothing else), the `artcal` program and P/lib/cmake/artcal/, so that a
# consumer writes
#   find_package(artcal REQUIRED)
#   target_link_libraries(app PRIVATE artcal::artcal)
# tests/consumer/ is such a consumer, built against an installed tree in the test suite.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

set(ARTCAL_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/artcal)

# The artcal headers `header` (relative to include/) includes, transitively, into `out`.
function(artcal_header_closure header out)
  set(done "")
  set(todo ${header})
  while(todo)
    list(POP_FRONT todo current)
    if(current IN_LIST done)
      continue()
    endif()
    list(APPEND done ${current})
    set(path ${PROJECT_SOURCE_DIR}/include/${current})
    if(NOT EXISTS ${path})
      message(FATAL_ERROR "public header ${current} not found (included from the umbrella)")
    endif()
    set_property(DIRECTORY APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS ${path})
    file(STRINGS ${path} lines REGEX "^#include \"artcal/")
    foreach(line ${lines})
      string(REGEX REPLACE "^#include \"(artcal/[^\"]+)\".*" "\\1" included "${line}")
      list(APPEND todo ${included})
    endforeach()
  endwhile()
  set(${out} ${done} PARENT_SCOPE)
endfunction()

artcal_header_closure(artcal/artcal.hpp ARTCAL_PUBLIC_HEADERS)
foreach(header ${ARTCAL_PUBLIC_HEADERS})
  get_filename_component(folder ${header} DIRECTORY)
  install(FILES ${PROJECT_SOURCE_DIR}/include/${header}
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/${folder})
endforeach()

# Every layer, exported as artcal::<layer> (the names the build's aliases use), the umbrella
# artcal::artcal and the warnings target the layers link privately (a static library's private
# links travel with it as link-only dependencies).
set(ARTCAL_EXPORTED_TARGETS artcal artcal_warnings)
foreach(layer core model artifact plan estimation calibration acceptance planning io report)
  list(APPEND ARTCAL_EXPORTED_TARGETS artcal_${layer})
  set_target_properties(artcal_${layer} PROPERTIES EXPORT_NAME ${layer})
endforeach()
set_target_properties(artcal_warnings PROPERTIES EXPORT_NAME warnings)
install(TARGETS ${ARTCAL_EXPORTED_TARGETS}
        EXPORT artcalTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
# OPTIONAL: the library installs after a build of the libraries alone (the program not built).
install(TARGETS artcal_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} OPTIONAL)
# The URDF module (src/urdf/urdf_module.hpp) where the loader looks: <prefix>/<libdir>/artcal/.
install(TARGETS artcal_urdf LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/artcal OPTIONAL)
install(EXPORT artcalTargets NAMESPACE artcal:: DESTINATION ${ARTCAL_INSTALL_CMAKEDIR})

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/artcalConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/artcalConfig.cmake
                              INSTALL_DESTINATION ${ARTCAL_INSTALL_CMAKEDIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/artcalConfigVersion.cmake
                                 COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/artcalConfig.cmake
              ${PROJECT_BINARY_DIR}/artcalConfigVersion.cmake
        DESTINATION ${ARTCAL_INSTALL_CMAKEDIR})
