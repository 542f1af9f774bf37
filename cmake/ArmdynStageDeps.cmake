# Stable copies of the build dependencies' headers and libraries, for a build directory that is
# reused across `pip install .` runs.
#
# Why: pip builds in isolation. Every run installs the build requirements (pybind11, the cmeel
# wheels of Eigen, urdfdom, tinyxml2, console_bridge) into a fresh /tmp/pip-build-env-XXXXXXXX,
# so the include paths on every compile line (and the library paths on the link line) change from
# one run to the next: ninja sees new command lines and recompiles everything, even though
# scikit-build-core keeps the build directory (`build-dir` in pyproject.toml).
#
# What: at configure time the headers and shared libraries of the imported targets are mirrored
# into <build>/_deps (a file is copied only when its content differs, so unchanged headers keep
# their timestamps), and the imported targets are pointed at those copies. The compile and link
# lines then name only stable paths, header dependencies stay valid, and an unchanged tree builds
# nothing; a changed dependency (a new pybind11 or Eigen release) changes the copied files, and
# exactly the translation units that include them are rebuilt.

set(ARMDYN_STAGE_DIR "${CMAKE_BINARY_DIR}/_deps")

# armdyn_stage_tree(<src> <dst> <entry>...): mirror the files and directories <entry> (relative
# to <src>; "." for all of it) into <dst>, copying only files whose content differs.
function(armdyn_stage_tree src dst)
  foreach(entry IN LISTS ARGN)
    if(IS_DIRECTORY "${src}/${entry}")
      file(GLOB_RECURSE files RELATIVE "${src}" "${src}/${entry}/*")
    elseif(EXISTS "${src}/${entry}")
      set(files "${entry}")
    else()
      message(FATAL_ERROR "armdyn: ${src}/${entry} does not exist (staging the dependencies)")
    endif()
    foreach(f IN LISTS files)
      get_filename_component(dir "${dst}/${f}" DIRECTORY)
      file(MAKE_DIRECTORY "${dir}")
      file(COPY_FILE "${src}/${f}" "${dst}/${f}" ONLY_IF_DIFFERENT)
    endforeach()
  endforeach()
endfunction()

# armdyn_stage_target(<target> <name> <entry>...): stage the (single) include directory of the
# imported <target> (the entries of it the build needs, "." for all) into _deps/<name>/include,
# and its shared library, if any, into _deps/lib under its SONAME; then point <target> there.
function(armdyn_stage_target target name)
  get_target_property(incs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  list(LENGTH incs n)
  if(NOT n EQUAL 1)
    message(FATAL_ERROR "armdyn: ${target} has ${n} include directories (${incs}), 1 expected")
  endif()
  set(staged "${ARMDYN_STAGE_DIR}/${name}/include")
  armdyn_stage_tree("${incs}" "${staged}" ${ARGN})
  set_property(TARGET ${target} PROPERTY INTERFACE_INCLUDE_DIRECTORIES "${staged}")

  get_target_property(type ${target} TYPE)
  if(NOT type STREQUAL "SHARED_LIBRARY")
    return()
  endif()
  get_target_property(configs ${target} IMPORTED_CONFIGURATIONS)
  set(suffixes "")
  if(configs)
    foreach(c IN LISTS configs)
      string(TOUPPER "${c}" c)
      list(APPEND suffixes "_${c}")
    endforeach()
  endif()
  list(APPEND suffixes "")
  foreach(sfx IN LISTS suffixes)
    get_target_property(loc ${target} IMPORTED_LOCATION${sfx})
    if(NOT loc)
      continue()
    endif()
    get_target_property(soname ${target} IMPORTED_SONAME${sfx})
    if(NOT soname)
      get_filename_component(soname "${loc}" NAME)
    endif()
    # the file under its SONAME: the name the linker looks for when another staged library
    # needs it, and the name the module records (DT_NEEDED) and finds at run time
    file(MAKE_DIRECTORY "${ARMDYN_STAGE_DIR}/lib")
    file(COPY_FILE "${loc}" "${ARMDYN_STAGE_DIR}/lib/${soname}" ONLY_IF_DIFFERENT)
    set_property(TARGET ${target} PROPERTY IMPORTED_LOCATION${sfx}
                                           "${ARMDYN_STAGE_DIR}/lib/${soname}")
  endforeach()
endfunction()
