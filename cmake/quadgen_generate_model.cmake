# quadgen_generate_model(TARGET <name> VEHICLE <vehicle.yaml> [EFFECTS e1,e2|all] [OUTPUT_DIR <dir>])
#
# Runs `quadgen derive <vehicle.yaml> --out <dir> [--effects ...]` at build time and creates
# the INTERFACE library <name>, whose include directories are <dir> and its parent: link it and
# `#include "model.hpp"` (namespace quadgen_generated::<vehicle name>[_with_<effects>...] or
# <vehicle name>_all_effects), or, where one translation unit uses two models (each header is
# named model.hpp), `#include "<name>/model.hpp"` for each (with the default <dir>; a given
# OUTPUT_DIR's parent is not put on the include path, which could be a whole source tree). The header is rebuilt when the vehicle file or the quadgen
# executable changes. <dir> (default: ${CMAKE_CURRENT_BINARY_DIR}/quadgen_models/<name>) is
# quadgen's own output directory (model.hpp, model.json, derivation.md): put nothing else in it.
# EFFECTS takes a comma-separated list, a CMake list, or `all`.
#
# The derive step uses the executable named by QUADGEN_EXECUTABLE if set, else the imported
# target quadgen::quadgen (from find_package(quadgen)).
include_guard(GLOBAL)

function(quadgen_generate_model)
  cmake_parse_arguments(QG "" "TARGET;VEHICLE;OUTPUT_DIR" "EFFECTS" ${ARGN})
  if(QG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "quadgen_generate_model: unknown arguments: ${QG_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT QG_TARGET)
    message(FATAL_ERROR "quadgen_generate_model: TARGET <name> is required")
  endif()
  if(NOT QG_VEHICLE)
    message(FATAL_ERROR "quadgen_generate_model: VEHICLE <vehicle.yaml> is required")
  endif()
  get_filename_component(vehicle "${QG_VEHICLE}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_SOURCE_DIR}")
  if(NOT EXISTS "${vehicle}")
    message(FATAL_ERROR "quadgen_generate_model: vehicle file ${vehicle} does not exist")
  endif()
  if(QG_OUTPUT_DIR)
    get_filename_component(out "${QG_OUTPUT_DIR}" ABSOLUTE BASE_DIR "${CMAKE_CURRENT_BINARY_DIR}")
  else()
    set(out "${CMAKE_CURRENT_BINARY_DIR}/quadgen_models/${QG_TARGET}")
  endif()
  get_filename_component(out_parent "${out}" DIRECTORY)

  if(QUADGEN_EXECUTABLE)
    set(exe "${QUADGEN_EXECUTABLE}")
    set(exe_dep "${QUADGEN_EXECUTABLE}")
  elseif(TARGET quadgen::quadgen)
    set(exe quadgen::quadgen)
    set(exe_dep "$<TARGET_FILE:quadgen::quadgen>")
  else()
    message(FATAL_ERROR "quadgen_generate_model: no quadgen executable (find_package(quadgen) or set QUADGEN_EXECUTABLE)")
  endif()

  set(effects_args)
  if(QG_EFFECTS)
    string(REPLACE ";" "," effects "${QG_EFFECTS}")
    set(effects_args --effects "${effects}")
  endif()

  add_custom_command(
    OUTPUT "${out}/model.hpp" "${out}/model.json" "${out}/derivation.md"
    COMMAND "${CMAKE_COMMAND}" -E make_directory "${out_parent}"
    COMMAND ${exe} derive "${vehicle}" --out "${out}" ${effects_args}
    DEPENDS "${vehicle}" "${exe_dep}"
    WORKING_DIRECTORY "${CMAKE_CURRENT_BINARY_DIR}"
    COMMENT "quadgen derive ${QG_VEHICLE} -> ${out}/model.hpp"
    VERBATIM)
  add_custom_target(${QG_TARGET}_quadgen_derive DEPENDS "${out}/model.hpp")
  add_library(${QG_TARGET} INTERFACE)
  target_include_directories(${QG_TARGET} INTERFACE "${out}")
  if(NOT QG_OUTPUT_DIR)  # quadgen_models/: only quadgen's folders, so "<name>/model.hpp" is safe to offer
    target_include_directories(${QG_TARGET} INTERFACE "${out_parent}")
  endif()
  target_compile_features(${QG_TARGET} INTERFACE cxx_std_17)
  add_dependencies(${QG_TARGET} ${QG_TARGET}_quadgen_derive)
  set_target_properties(${QG_TARGET} PROPERTIES QUADGEN_MODEL_HEADER "${out}/model.hpp")
endfunction()
