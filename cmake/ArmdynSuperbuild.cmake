# The pip build (scikit-build-core) as a thin wrapper around an inner CMake build.
#
# Why: pip builds in an isolated environment created afresh on every `pip install .`, and
# scikit-build-core, seeing a new environment, deletes <build-dir>/CMakeCache.txt and
# <build-dir>/CMakeFiles (where the object files live) even with the persistent `build-dir` of
# pyproject.toml: every install recompiled everything. The module is therefore configured and
# built in <build-dir>/inner, a build tree of its own that nothing deletes; this outer project
# only (re)configures it, builds it (`cmake --build`, which recompiles what changed and nothing
# else) and installs the module it produced. The inner tree compiles against stable copies of
# the dependencies (cmake/ArmdynStageDeps.cmake), since the isolated environment moves them.

set(ARMDYN_INNER_DIR "${CMAKE_BINARY_DIR}/inner")

# what the inner build needs from the outer configuration
set(_args
    -DARMDYN_INNER_BUILD=ON
    -DARMDYN_PYTHON=ON
    -DARMDYN_INSTALL=OFF
    "-DCMAKE_BUILD_TYPE=${CMAKE_BUILD_TYPE}"
    "-DPython_EXECUTABLE=${Python_EXECUTABLE}"
    # the defaults of a pip build (docs/install.md, "Build time")
    -DARMDYN_UNITY_BUILD=ON
    -DARMDYN_COLD_OPTIONS=-O1)
if(CMAKE_MAKE_PROGRAM)
  list(APPEND _args "-DCMAKE_MAKE_PROGRAM=${CMAKE_MAKE_PROGRAM}")
endif()
# settings a user may pass to pip (-C cmake.define.X=... or CMAKE_ARGS) reach the inner build
foreach(
  var IN
  ITEMS CMAKE_CXX_COMPILER
        CMAKE_CXX_FLAGS
        CMAKE_CXX_FLAGS_RELEASE
        CMAKE_CXX_COMPILER_LAUNCHER
        CMAKE_INTERPROCEDURAL_OPTIMIZATION
        ARMDYN_UNITY_BUILD
        ARMDYN_COLD_OPTIONS)
  if(DEFINED ${var})
    list(APPEND _args "-D${var}=${${var}}")
  endif()
endforeach()
# package locations found by the previous run point into its (deleted) isolated environment:
# forget them, they are searched again
foreach(pkg IN ITEMS Eigen3 urdfdom urdfdom_headers console_bridge tinyxml2 pybind11)
  list(APPEND _args "-U${pkg}_DIR")
endforeach()

message(STATUS "armdyn: configuring the inner build in ${ARMDYN_INNER_DIR}")
execute_process(
  COMMAND "${CMAKE_COMMAND}" -S "${CMAKE_SOURCE_DIR}" -B "${ARMDYN_INNER_DIR}" -G
          "${CMAKE_GENERATOR}" ${_args}
  RESULT_VARIABLE _rc)
if(NOT _rc EQUAL 0)
  message(FATAL_ERROR "armdyn: configuring the inner build failed (${_rc}); see above")
endif()

# always run: the inner build tool decides what is out of date
add_custom_target(
  armdyn_inner ALL
  COMMAND "${CMAKE_COMMAND}" --build "${ARMDYN_INNER_DIR}"
  USES_TERMINAL
  COMMENT "armdyn: building the module in ${ARMDYN_INNER_DIR}")

# the module the inner build produced (one Python ABI per build directory: <build-dir> is
# build/{wheel_tag}); its RPATH is final (BUILD_WITH_INSTALL_RPATH)
install(
  CODE "file(GLOB _armdyn_module \"${ARMDYN_INNER_DIR}/_core.*\")
list(FILTER _armdyn_module INCLUDE REGEX \"/_core\\\\.[^/]*(so|pyd|dylib)$\")
list(LENGTH _armdyn_module _n)
if(NOT _n EQUAL 1)
  message(FATAL_ERROR \"armdyn: expected one module in ${ARMDYN_INNER_DIR}, found: \${_armdyn_module}\")
endif()
file(INSTALL \${_armdyn_module} DESTINATION \"\${CMAKE_INSTALL_PREFIX}/armdyn\")"
  COMPONENT python)
