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

# follicle_module(name DEPS <targets...>): a static library from every .cpp in the folder.
# Headers live beside sources and are included as <follicle/<name>/x.hpp>.
function(follicle_module name)
  cmake_parse_arguments(ARG "" "" "DEPS;PRIVATE_DEPS" ${ARGN})
  file(GLOB srcs CONFIGURE_DEPENDS ${CMAKE_CURRENT_SOURCE_DIR}/*.cpp)
  if(NOT srcs)
    # Header-only so far.
    add_library(follicle_${name} INTERFACE)
    add_library(follicle::${name} ALIAS follicle_${name})
    target_include_directories(follicle_${name} INTERFACE ${PROJECT_SOURCE_DIR}/src)
    target_link_libraries(follicle_${name} INTERFACE ${ARG_DEPS})
    return()
  endif()
  add_library(follicle_${name} STATIC ${srcs})
  add_library(follicle::${name} ALIAS follicle_${name})
  target_include_directories(follicle_${name} PUBLIC ${PROJECT_SOURCE_DIR}/src)
  target_link_libraries(follicle_${name} PUBLIC ${ARG_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
  set_target_properties(follicle_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  follicle_target_settings(follicle_${name})
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
  set(labels unit ${ARG_LABELS})
  gtest_discover_tests(test_${name}
    WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
    PROPERTIES LABELS "${labels}" ENVIRONMENT "FOLLICLE_SOURCE_DIR=${PROJECT_SOURCE_DIR}"
    DISCOVERY_TIMEOUT 60)
endfunction()
