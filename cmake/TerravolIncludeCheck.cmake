# The one-way dependencies between the project's folders (docs/architecture.md, "Layout"),
# checked as part of the build. Every target adds the project root as an include root (and
# Debian's third-party headers all live in /usr/include), so a header of another folder is
# always found by the compiler; instead, before a target compiles, cmake/check_includes.cmake
# reads every #include of its sources and of the headers in its folder and fails the build on
# one that the target may not use:
#   terravol_check_includes(TARGET [SOURCES_ONLY] ALLOW folder... [FORBID regex...])
# ALLOW: the project folders (first path parts, e.g. io, app/scene) whose headers the target
# may include; includes of any other project folder fail. FORBID: regular expressions of
# third-party includes the target may not use (e.g. "^vtk" for no VTK, "^CLI/" for no CLI11).
# SOURCES_ONLY: the target's sources alone, not the folder's headers (an executable beside the
# folder's library). The check runs again whenever one of those files changes.
set(TERRAVOL_PROJECT_FOLDERS app bench coverage density fuzz io mrbsp objects reference tests tiler volume)

function(terravol_check_includes target)
  cmake_parse_arguments(PARSE_ARGV 1 arg "SOURCES_ONLY" "" "ALLOW;FORBID")
  get_target_property(dir ${target} SOURCE_DIR)
  get_target_property(sources ${target} SOURCES)
  set(headers)
  if(NOT arg_SOURCES_ONLY)
    file(GLOB headers CONFIGURE_DEPENDS ${dir}/*.h)
  endif()
  set(files)
  foreach(s IN LISTS sources headers)
    if(NOT IS_ABSOLUTE "${s}")
      set(s "${dir}/${s}")
    endif()
    list(APPEND files "${s}")
  endforeach()
  list(REMOVE_DUPLICATES files)
  set(config "${CMAKE_CURRENT_BINARY_DIR}/${target}.includes.cmake")
  set(stamp "${CMAKE_CURRENT_BINARY_DIR}/${target}.includes.stamp")
  file(CONFIGURE OUTPUT "${config}" CONTENT [[
set(TARGET "@target@")
set(FILES "@files@")
set(ALLOW "@arg_ALLOW@")
set(FORBID "@arg_FORBID@")
set(PROJECT_FOLDERS "@TERRAVOL_PROJECT_FOLDERS@")
set(ROOT "@PROJECT_SOURCE_DIR@")
]] @ONLY)
  add_custom_command(OUTPUT "${stamp}"
    COMMAND ${CMAKE_COMMAND} -DCONFIG=${config} -DSTAMP=${stamp} -P ${PROJECT_SOURCE_DIR}/cmake/check_includes.cmake
    DEPENDS ${files} "${config}" ${PROJECT_SOURCE_DIR}/cmake/check_includes.cmake
    COMMENT "Checking the includes of ${target}"
    VERBATIM)
  add_custom_target(${target}_includes DEPENDS "${stamp}")
  add_dependencies(${target} ${target}_includes)
endfunction()
