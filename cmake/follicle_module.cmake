# Shared compile settings for Follicle's own targets.
function(follicle_target_settings tgt)
  target_compile_options(${tgt} PRIVATE -Wall -Wextra -Wpedantic -Wshadow -Wno-unused-parameter)
  if(FOLLICLE_WERROR)
    target_compile_options(${tgt} PRIVATE -Werror)
  endif()
  if(FOLLICLE_SANITIZE)
    target_compile_options(${tgt} PRIVATE -fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
    # GCC's -Wmaybe-uninitialized gives false positives under -fsanitize (documented in the GCC
    # manual; seen in libstdc++ <regex> and std::function), so it is not an error in this build.
    target_compile_options(${tgt} PRIVATE -Wno-maybe-uninitialized)
    target_link_options(${tgt} PRIVATE -fsanitize=address,undefined)
  endif()
endfunction()

include(GNUInstallDirs)

# follicle_module(name DEPS <targets...>): a static library from every .cpp in the folder.
# Headers live beside sources and are included as <follicle/<name>/x.hpp>.
# Each module is installed (library + its .hpp) into the export set FollicleTargets as
# Follicle::<name>; cmake/install.cmake writes the package (see docs/install.md).
function(follicle_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  file(GLOB hdrs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.hpp)
  set(tgt follicle_${name})
  set(includes $<BUILD_INTERFACE:${PROJECT_SOURCE_DIR}/src>
               $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
  if(NOT srcs)
    # Header-only so far.
    add_library(${tgt} INTERFACE)
    target_include_directories(${tgt} INTERFACE ${includes})
    target_link_libraries(${tgt} INTERFACE ${ARG_DEPS})
    target_compile_features(${tgt} INTERFACE cxx_std_20)
  else()
    add_library(${tgt} STATIC ${srcs})
    target_include_directories(${tgt} PUBLIC ${includes})
    # A static library's private dependencies still reach its consumers' link line
    # ($<LINK_ONLY:...>), so FollicleConfig.cmake finds every one of them (find_dependency).
    target_link_libraries(${tgt} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    target_compile_features(${tgt} PUBLIC cxx_std_20)  # the headers need it; consumers get it too
    set_target_properties(${tgt} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    follicle_target_settings(${tgt})
  endif()
  add_library(follicle::${name} ALIAS ${tgt})
  set_target_properties(${tgt} PROPERTIES EXPORT_NAME ${name})
  set_property(GLOBAL APPEND PROPERTY FOLLICLE_MODULES ${tgt})
  install(TARGETS ${tgt} EXPORT FollicleTargets
          ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT Follicle_Development)
  install(FILES ${hdrs} DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/follicle/${name}
          COMPONENT Follicle_Development)
endfunction()

# follicle_test(name LIBS <targets...>): one GoogleTest program from tests/unit/<name>/*.cpp and
# tests/physics/<name>/*.cpp; each test case becomes a CTest test.
function(follicle_test name)
  cmake_parse_arguments(ARG "" "" "LIBS;LABELS" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS
       ${PROJECT_SOURCE_DIR}/tests/unit/${name}/*.cpp
       ${PROJECT_SOURCE_DIR}/tests/physics/${name}/*.cpp)
  if(NOT srcs)
    return()
  endif()
  add_executable(test_${name} ${srcs})
  target_link_libraries(test_${name} PRIVATE ${ARG_LIBS} follicle_testing GTest::gtest GTest::gmock)
  follicle_target_settings(test_${name})
  # One label only: gtest_discover_tests writes PROPERTIES unquoted into its script, so a list
  # "unit;slow" became LABELS unit plus a stray property "slow" and -LE slow never excluded the
  # soak. A program with its own label (gl, slow) carries that instead of "unit".
  set(labels unit)
  if(ARG_LABELS)
    list(GET ARG_LABELS 0 labels)
  endif()
  gtest_discover_tests(test_${name}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${labels}" ENVIRONMENT "FOLLICLE_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    DISCOVERY_TIMEOUT 60)
endfunction()
