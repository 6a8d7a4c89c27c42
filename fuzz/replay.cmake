# The fuzz targets as ctest smoke tests in the ordinary (g++) builds: fuzz_replay_<name> links a
# target's LLVMFuzzerTestOneInput with fuzz/replay_main.cpp (no libFuzzer) and runs it over the
# committed seeds, the regression reproducers and a fixed number of seeded mutations. Under the
# asan preset they run with AddressSanitizer + UBSan. Label "fuzz"; docs/reliability.md.
set(FOLLICLE_FUZZ_REPLAY_MUTATIONS 5000 CACHE STRING "mutations per fuzz target in the ctest smoke pass")
set(_fuzz ${PROJECT_SOURCE_DIR}/fuzz)
function(follicle_fuzz_replay name)
  cmake_parse_arguments(ARG "" "MUTATIONS" "LIBS" ${ARGN})
  add_executable(fuzz_replay_${name} ${_fuzz}/fuzz_${name}.cpp ${_fuzz}/replay_main.cpp)
  target_link_libraries(fuzz_replay_${name} PRIVATE ${ARG_LIBS})
  follicle_target_settings(fuzz_replay_${name})
  set(_n ${FOLLICLE_FUZZ_REPLAY_MUTATIONS})
  if(ARG_MUTATIONS)
    math(EXPR _n "${FOLLICLE_FUZZ_REPLAY_MUTATIONS} * ${ARG_MUTATIONS} / 100")
  endif()
  set(_inputs ${_fuzz}/corpus/${name})
  if(EXISTS ${_fuzz}/regressions/${name})
    list(APPEND _inputs ${_fuzz}/regressions/${name})
  endif()
  add_test(NAME fuzz.replay.${name}
           COMMAND fuzz_replay_${name} --mutations ${_n} --seed 1 --dict ${_fuzz}/dict/${name}.dict
                   --crash-dir ${CMAKE_CURRENT_BINARY_DIR}/fuzz_replay/${name} ${_inputs})
  set_tests_properties(fuzz.replay.${name} PROPERTIES LABELS fuzz TIMEOUT 600)
endfunction()

# MUTATIONS: percent of the default count, for the slow readers (OpenEXR allocates per input).
follicle_fuzz_replay(obj LIBS follicle::geom)
follicle_fuzz_replay(ply LIBS follicle::geom)
follicle_fuzz_replay(gltf LIBS follicle::geom)
follicle_fuzz_replay(hair LIBS follicle::geom)
follicle_fuzz_replay(tfx LIBS follicle::geom)
follicle_fuzz_replay(usda LIBS follicle::geom)
follicle_fuzz_replay(obj_strands LIBS follicle::geom)
follicle_fuzz_replay(png LIBS follicle::image)
follicle_fuzz_replay(exr LIBS follicle::image MUTATIONS 5)
follicle_fuzz_replay(face_setup LIBS follicle::skin)
follicle_fuzz_replay(scene LIBS follicle::scene)
