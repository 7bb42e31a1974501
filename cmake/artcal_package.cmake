# A Debian package (issue 33): from a Release build,
#   cpack -G DEB --config build/CPackConfig.cmake -B OUT      (or: cd build && cpack -G DEB)
# makes OUT/artcal_<version>_<arch>.deb holding what `cmake --install` installs under /usr: the
# `artcal` program, the layer libraries with the public headers and lib/cmake/artcal, and the
# Python module when it was built (lib/python3.X/dist-packages/artcal). On a fresh Debian 12,
# `apt install ./artcal_*.deb` pulls its dependencies: the shared libraries the program and the
# module link (dpkg-shlibdeps), Python and numpy for the module, and the -dev packages whose CMake
# configurations artcalConfig.cmake finds (find_dependency) for a downstream build.
# tests/package/run_package.cmake builds it, unpacks it with dpkg -x into a scratch root and
# builds tests/consumer against that root.
set(CPACK_PACKAGE_NAME artcal)
set(CPACK_PACKAGE_VENDOR "artcal")
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
    "Kinematic calibration of measuring mechanisms: plan, evaluate, calibrate, verify")
set(CPACK_PACKAGE_CONTACT "artcal developers <artcal@localhost>")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(ARTCAL_DEB_DEPENDS
    "libeigen3-dev (>= 3.4), libnlopt-cxx-dev, nlohmann-json3-dev (>= 3.10)")
if(ARTCAL_PYTHON_BUILT)
  math(EXPR ARTCAL_PYTHON_NEXT_MINOR "${Python3_VERSION_MINOR} + 1")
  string(APPEND ARTCAL_DEB_DEPENDS
         ", python3 (>= ${Python3_VERSION_MAJOR}.${Python3_VERSION_MINOR}), python3 (<< ${Python3_VERSION_MAJOR}.${ARTCAL_PYTHON_NEXT_MINOR}), python3-numpy")
endif()
set(CPACK_DEBIAN_PACKAGE_DEPENDS "${ARTCAL_DEB_DEPENDS}")
set(CPACK_GENERATOR DEB)
include(CPack)
