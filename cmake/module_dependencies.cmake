# reads src/penumbra/DEPENDENCIES (its header describes the format): one line per module,
# `module: dep dep ...`, '#' starting a comment. after penumbra_read_dependencies(<file>),
# PENUMBRA_MODULES lists the modules in file order and PENUMBRA_DEPS_<module> the deps of each.
# a sub-module (a sub-folder with its own line, e.g. render/cpu) is named by its path;
# penumbra_module_target(<module> <var>) gives its library name (penumbra_render_cpu).
# scripts/check_module_deps.py parses the same file; tests/meta checks both read it alike.
#
# script mode prints the parsed table, one "module: deps" line each, to stderr:
#   cmake -DPENUMBRA_DEPENDENCIES=src/penumbra/DEPENDENCIES -P cmake/module_dependencies.cmake

if(CMAKE_SCRIPT_MODE_FILE)
  cmake_minimum_required(VERSION 3.22)
endif()

function(penumbra_read_dependencies table)
  file(READ "${table}" text)
  # list separators and brackets only occur in comments; they would split or join list items
  string(REGEX REPLACE "[][;]" " " text "${text}")
  string(REPLACE "\n" ";" lines "${text}")
  set(modules "")
  set(n 0)
  foreach(line IN LISTS lines)
    math(EXPR n "${n} + 1")
    string(REGEX REPLACE "#.*$" "" line "${line}")
    string(STRIP "${line}" line)
    if(line STREQUAL "")
      continue()
    endif()
    if(NOT line MATCHES "^([a-z][a-z0-9_]*(/[a-z][a-z0-9_]*)*)[ \t]*:(.*)$")
      message(FATAL_ERROR "${table}:${n}: got '${line}'; expected 'module: dep dep ...'")
    endif()
    set(module "${CMAKE_MATCH_1}")
    string(REGEX MATCHALL "[^ \t\r]+" deps "${CMAKE_MATCH_3}")
    if(module IN_LIST modules)
      message(FATAL_ERROR "${table}:${n}: module '${module}' has a second line")
    endif()
    list(APPEND modules "${module}")
    set(PENUMBRA_DEPS_${module} "${deps}" PARENT_SCOPE)
  endforeach()
  set(PENUMBRA_MODULES "${modules}" PARENT_SCOPE)
endfunction()

function(penumbra_module_target module out_var)
  string(REPLACE "/" "_" target "penumbra_${module}")
  set(${out_var} "${target}" PARENT_SCOPE)
endfunction()

if(CMAKE_SCRIPT_MODE_FILE AND DEFINED PENUMBRA_DEPENDENCIES)
  penumbra_read_dependencies("${PENUMBRA_DEPENDENCIES}")
  foreach(module IN LISTS PENUMBRA_MODULES)
    list(JOIN PENUMBRA_DEPS_${module} " " deps)
    message(NOTICE "${module}: ${deps}")
  endforeach()
endif()
