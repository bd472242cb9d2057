# What each fuzz target (fuzz/fuzz_NAME.cpp) links, and the stage label of its
# regression replay in ctest. Used by fuzz/CMakeLists.txt (the libFuzzer
# executables) and tests/CMakeLists.txt (the replays in the normal build).
set(_pbfuzz_libs_fuzz_experiment_yaml pb_runner)
set(_pbfuzz_libs_fuzz_training_cache pb_recognition)
set(_pbfuzz_libs_fuzz_records_jsonl pb_eval pb_io)  # with runner/store.cpp itself: PCL-free
set(_pbfuzz_libs_fuzz_scene_yaml pb_scenes)
set(_pbfuzz_libs_fuzz_models_yaml pb_models)
set(_pbfuzz_libs_fuzz_bop_results_csv pb_eval)
set(_pbfuzz_stage_fuzz_experiment_yaml runner)
set(_pbfuzz_stage_fuzz_records_jsonl runner)
set(_pbfuzz_stage_fuzz_training_cache recognition)
set(_pbfuzz_stage_fuzz_scene_yaml scenes)
set(_pbfuzz_stage_fuzz_models_yaml models)
set(_pbfuzz_stage_fuzz_bop_results_csv eval)
file(GLOB POSEBENCH_FUZZ_SOURCES CONFIGURE_DEPENDS ${CMAKE_CURRENT_LIST_DIR}/fuzz_*.cpp)

# posebench_fuzz_executable(TARGET NAME SOURCES...): TARGET built from
# fuzz/NAME.cpp and SOURCES, with NAME's libraries. Sets PBFUZZ_STAGE.
function(posebench_fuzz_executable target name)
  set(_extra)
  if(name STREQUAL "fuzz_records_jsonl")
    set(_extra ${PROJECT_SOURCE_DIR}/src/runner/store.cpp)
  endif()
  add_executable(${target} ${PROJECT_SOURCE_DIR}/fuzz/${name}.cpp ${_extra} ${ARGN})
  target_include_directories(${target} PRIVATE ${PROJECT_SOURCE_DIR}/src ${PROJECT_SOURCE_DIR}/fuzz)
  target_compile_options(${target} PRIVATE ${POSEBENCH_WARNINGS})
  if(DEFINED _pbfuzz_libs_${name})
    target_link_libraries(${target} PRIVATE ${_pbfuzz_libs_${name}})
  else()
    target_link_libraries(${target} PRIVATE pb_io)
  endif()
  if(DEFINED _pbfuzz_stage_${name})
    set(PBFUZZ_STAGE ${_pbfuzz_stage_${name}} PARENT_SCOPE)
  else()
    set(PBFUZZ_STAGE io PARENT_SCOPE)
  endif()
endfunction()
