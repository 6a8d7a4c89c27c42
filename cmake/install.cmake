# The installable CMake package Follicle (docs/install.md):
#   cmake --install <build> --prefix P
# writes P/include/follicle/<module>/*.hpp, P/<libdir>/libfollicle_<module>.a (follicle_module()
# installs both), P/<libdir>/cmake/Follicle/ (package config, below) and P/bin/follicle (apps/cli).
# A consumer: find_package(Follicle CONFIG REQUIRED) + target_link_libraries(app PRIVATE
# Follicle::follicle) (or one module: Follicle::geom, Follicle::scene, ...).
include(CMakePackageConfigHelpers)

set(FOLLICLE_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/Follicle)

# Follicle::follicle: every module (follicle::follicle in this build tree).
get_property(_follicle_modules GLOBAL PROPERTY FOLLICLE_MODULES)
add_library(follicle_all INTERFACE)
add_library(follicle::follicle ALIAS follicle_all)
target_link_libraries(follicle_all INTERFACE ${_follicle_modules})
set_target_properties(follicle_all PROPERTIES EXPORT_NAME follicle)
install(TARGETS follicle_all EXPORT FollicleTargets COMPONENT Follicle_Development)

# Module names (core, geom, ...) for FollicleConfig.cmake's COMPONENTS check.
list(TRANSFORM _follicle_modules REPLACE "^follicle_" "" OUTPUT_VARIABLE _follicle_names)
list(JOIN _follicle_names " " FOLLICLE_PACKAGE_MODULES)

install(EXPORT FollicleTargets
        NAMESPACE Follicle::
        DESTINATION ${FOLLICLE_INSTALL_CMAKEDIR}
        COMPONENT Follicle_Development)
configure_package_config_file(
  ${CMAKE_CURRENT_LIST_DIR}/FollicleConfig.cmake.in
  ${CMAKE_CURRENT_BINARY_DIR}/FollicleConfig.cmake
  INSTALL_DESTINATION ${FOLLICLE_INSTALL_CMAKEDIR})
# 0.x: a minor version may break the API, so only the same major.minor is compatible.
write_basic_package_version_file(
  ${CMAKE_CURRENT_BINARY_DIR}/FollicleConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/FollicleConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/FollicleConfigVersion.cmake
        DESTINATION ${FOLLICLE_INSTALL_CMAKEDIR}
        COMPONENT Follicle_Development)

# Test: install this build into a temporary prefix, build examples/ against it, run it on a mesh.
# Not under the sanitizers: the installed static libraries would need -fsanitize in the consumer.
if(FOLLICLE_BUILD_TESTS AND NOT FOLLICLE_SANITIZE)
  # --opt=value: one argument each, even when the value is empty.
  set(_follicle_install_test_args
      --cmake=${CMAKE_COMMAND}
      --build-dir=${CMAKE_BINARY_DIR}
      --source-dir=${PROJECT_SOURCE_DIR}
      --config=$<CONFIG>
      --cxx=${CMAKE_CXX_COMPILER}
      --mesh=${PROJECT_SOURCE_DIR}/data/meshes/torus/torus.obj)
  if(CMAKE_GENERATOR MATCHES "Ninja")
    list(APPEND _follicle_install_test_args --ninja=${CMAKE_MAKE_PROGRAM})
  endif()
  list(LENGTH CMAKE_CXX_COMPILER_LAUNCHER _n)
  if(_n EQUAL 1)  # e.g. ccache: the example then compiles from the cache on reruns
    list(APPEND _follicle_install_test_args --launcher=${CMAKE_CXX_COMPILER_LAUNCHER})
  endif()
  add_test(NAME install.consumer
           COMMAND bash ${PROJECT_SOURCE_DIR}/tests/install/install_consumer.sh
                   ${_follicle_install_test_args})
  set_tests_properties(install.consumer PROPERTIES LABELS "unit;install" TIMEOUT 600)
endif()
