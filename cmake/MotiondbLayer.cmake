# motiondb_layer(TARGET SOURCES... [PUBLIC_DEPS deps...] [PRIVATE_DEPS deps...] [UNITY_BATCH N])
#
# A layer: one folder, one static library. Its headers are reachable only through the targets
# that link it, so a wrong-way include (core including server/, say) fails to compile instead of
# merely reading wrong. The folder's *.h files are linked into a staging root of their own,
# <build>/include/TARGET/<folder>/, which is the target's public include directory; headers in
# the folder's internal/ are staged into a private root that only the target itself sees. The
# source tree itself is on no include path.
#
# UNITY_BATCH N compiles the sources N to a translation unit (CMake's unity build), for layers
# whose every file includes the same heavy headers: CLI11 alone costs about 10 s a file at -O3
# (its header defines global validators, so each file compiles its whole parser), the generated
# gRPC service headers about 5 s. A layer so built keeps its files' names distinct inside its
# anonymous namespaces. -DMOTIONDB_UNITY_BUILD=OFF compiles every file alone (for tools that
# read compile_commands.json file by file, or to check that each file includes what it uses).
function(motiondb_layer target)
  cmake_parse_arguments(ARG "" "UNITY_BATCH" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  if(ARG_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "motiondb_layer(${target}): unknown arguments ${ARG_UNPARSED_ARGUMENTS}")
  endif()
  if("UNITY_BATCH" IN_LIST ARG_KEYWORDS_MISSING_VALUES)
    message(FATAL_ERROR "motiondb_layer(${target}): UNITY_BATCH needs a count of files a unit")
  endif()
  file(RELATIVE_PATH folder "${PROJECT_SOURCE_DIR}" "${CMAKE_CURRENT_SOURCE_DIR}")
  set(public_root "${CMAKE_BINARY_DIR}/include/${target}")
  set(private_root "${CMAKE_BINARY_DIR}/include/${target}.internal")
  motiondb_stage_headers("${CMAKE_CURRENT_SOURCE_DIR}" "${public_root}/${folder}")
  motiondb_stage_headers("${CMAKE_CURRENT_SOURCE_DIR}/internal" "${private_root}/${folder}/internal")
  if(ARG_SOURCES)
    add_library(${target} STATIC ${ARG_SOURCES})
    target_include_directories(${target} PUBLIC "${public_root}" PRIVATE "${private_root}")
    target_link_libraries(${target} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS})
    if(ARG_UNITY_BATCH AND MOTIONDB_UNITY_BUILD)
      set_target_properties(${target} PROPERTIES UNITY_BUILD ON
                                                 UNITY_BUILD_BATCH_SIZE ${ARG_UNITY_BATCH})
    endif()
  else()  # headers only
    add_library(${target} INTERFACE)
    target_include_directories(${target} INTERFACE "${public_root}")
    target_link_libraries(${target} INTERFACE ${ARG_PUBLIC_DEPS})
  endif()
endfunction()

# Links every *.h of `from` (not its subfolders) into `to`, replacing what was staged there
# before, so that a deleted or moved header stops resolving.
function(motiondb_stage_headers from to)
  file(REMOVE_RECURSE "${to}")
  file(GLOB headers CONFIGURE_DEPENDS "${from}/*.h")
  if(headers)
    file(MAKE_DIRECTORY "${to}")
  endif()
  foreach(header ${headers})
    get_filename_component(name "${header}" NAME)
    file(CREATE_LINK "${header}" "${to}/${name}" SYMBOLIC)
  endforeach()
endfunction()
