# Modules: each is a folder of sources and internal headers, src/<name>/, a folder of public
# headers, include/finecap/<name>/, and a static library finecap_<name> that links only the modules
# it names, which must already exist: modules are added bottom-up, so their graph has no cycle.
#
# Each module's include directories show its own headers and nothing else, so that an include
# against the direction fails to compile instead of merely being frowned upon. The build tree holds
# one root per module whose only entry is a link to that module's folder:
#
#   <build>/module_include/<name>/finecap/<name>  -> include/finecap/<name>   (public)
#   <build>/module_internal/<name>/<name>         -> src/<name>               (internal)
#
# finecap_<name> puts the public root on its PUBLIC include path, so a module sees the public
# headers of the modules it links ("finecap/util/error.h") and of no other. The internal root is on
# the target finecap_<name>_internal: the module itself and the modules above it link that
# privately and include "util/io_util.h"; a library user never does. Tests may link it too.
#
# The links of every module are recorded (finecap_write_module_graph), and a test compares them with
# the module graph docs/architecture.md draws.

function(finecap_add_module name)
  cmake_parse_arguments(ARG "" "" "DEPENDS;LIBRARIES" ${ARGN})
  foreach(dependency ${ARG_DEPENDS})
    if(NOT TARGET finecap_${dependency})
      message(FATAL_ERROR "module '${name}' depends on '${dependency}', which is not a module "
        "added before it (modules are added bottom-up)")
    endif()
  endforeach()

  set(public_root ${PROJECT_BINARY_DIR}/module_include/${name})
  set(internal_root ${PROJECT_BINARY_DIR}/module_internal/${name})
  file(MAKE_DIRECTORY ${public_root}/finecap ${internal_root})
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/include/finecap/${name} ${public_root}/finecap/${name}
    SYMBOLIC)
  file(CREATE_LINK ${PROJECT_SOURCE_DIR}/src/${name} ${internal_root}/${name} SYMBOLIC)

  file(GLOB_RECURSE sources CONFIGURE_DEPENDS ${PROJECT_SOURCE_DIR}/src/${name}/*.cc)
  # A piece of a module may keep its tests beside it (src/energy/terms/<term>/*_test.cc): they
  # belong to the tests' executable, not the library.
  list(FILTER sources EXCLUDE REGEX "_test\\.cc$")
  add_library(finecap_${name} STATIC ${sources})
  target_include_directories(finecap_${name} PUBLIC ${public_root})
  add_library(finecap_${name}_internal INTERFACE)
  target_include_directories(finecap_${name}_internal INTERFACE ${internal_root})
  target_link_libraries(finecap_${name}_internal INTERFACE finecap_${name})
  target_include_directories(finecap_${name} PRIVATE ${internal_root})
  foreach(dependency ${ARG_DEPENDS})
    target_link_libraries(finecap_${name}
      PUBLIC finecap_${dependency} PRIVATE finecap_${dependency}_internal)
  endforeach()
  target_link_libraries(finecap_${name} PUBLIC ${ARG_LIBRARIES})
  if(BUILD_SHARED_LIBS)
    set_target_properties(finecap_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
  endif()

  set_property(GLOBAL APPEND PROPERTY FINECAP_MODULES ${name})
  set_property(GLOBAL PROPERTY FINECAP_MODULE_SOURCES_${name} ${sources})
endfunction()

# The sources of module `name`, for a build that compiles them again with other flags (the fuzz
# targets).
function(finecap_module_sources name out)
  get_property(sources GLOBAL PROPERTY FINECAP_MODULE_SOURCES_${name})
  set(${out} ${sources} PARENT_SCOPE)
endfunction()

# The modules that `target` links directly, read from the target itself (not from what
# finecap_add_module was asked for), so that a link added by hand shows up too.
function(finecap_linked_modules target out)
  get_property(modules GLOBAL PROPERTY FINECAP_MODULES)
  get_target_property(links ${target} LINK_LIBRARIES)
  set(linked "")
  foreach(link ${links})
    foreach(module ${modules})
      if(link STREQUAL "finecap_${module}" OR link STREQUAL "finecap_${module}_internal")
        list(APPEND linked ${module})
      endif()
    endforeach()
  endforeach()
  list(REMOVE_ITEM linked ${ARGN})
  list(REMOVE_DUPLICATES linked)
  list(SORT linked)
  set(${out} ${linked} PARENT_SCOPE)
endfunction()

# The libraries of every module, top-down, in `libraries`, and their internal targets in
# `internals` (what the tests link).
function(finecap_module_targets libraries internals)
  get_property(modules GLOBAL PROPERTY FINECAP_MODULES)
  list(REVERSE modules)
  set(public "")
  set(internal "")
  foreach(module ${modules})
    list(APPEND public finecap_${module})
    list(APPEND internal finecap_${module}_internal)
  endforeach()
  set(${libraries} ${public} PARENT_SCOPE)
  set(${internals} ${internal} PARENT_SCOPE)
endfunction()

# Writes `file` with one line per module, "<module> -> <modules it links>", top-down.
function(finecap_write_module_graph file)
  get_property(modules GLOBAL PROPERTY FINECAP_MODULES)
  set(lines "")
  list(REVERSE modules)
  foreach(module ${modules})
    finecap_linked_modules(finecap_${module} linked ${module})
    string(REPLACE ";" " " linked "${linked}")
    string(STRIP "${module} -> ${linked}" line)
    string(APPEND lines "${line}\n")
  endforeach()
  file(WRITE ${file} "${lines}")
endfunction()
