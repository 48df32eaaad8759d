# pnpba_module(NAME): finishes the library target pnpba_NAME as a pnpba module: the alias
# pnpba::NAME, its public headers (NAME/include, installed to <prefix>/include), the exported
# name pnpba::NAME, and its place in the install (cmake/PnpbaInstall.cmake).
function(pnpba_module name)
  set(target pnpba_${name})
  add_library(pnpba::${name} ALIAS ${target})
  target_include_directories(${target} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include> $<INSTALL_INTERFACE:include>)
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${name})
  set_property(GLOBAL APPEND PROPERTY PNPBA_MODULES ${name})
endfunction()

# pnpba_plugin(NAME SOURCES...): the shared module libpnpba_NAME.so, opened on first use by
# core's plugin loader (core/include/pnpba/core/plugin.h): built into lib/pnpba of the build
# tree, installed to <libdir>/pnpba, tagged with this build's plugin ABI.
function(pnpba_plugin name)
  set(target pnpba_${name})
  add_library(${target} MODULE ${ARGN} ${PROJECT_SOURCE_DIR}/cmake/plugin_abi.cpp)
  # Only the entry points marked visible are exported: a source a plugin shares with a module
  # library keeps its own copy private.
  set_target_properties(${target} PROPERTIES LIBRARY_OUTPUT_DIRECTORY ${PNPBA_PLUGIN_BUILD_DIR}
                                             CXX_VISIBILITY_PRESET hidden
                                             VISIBILITY_INLINES_HIDDEN ON)
  target_compile_definitions(${target} PRIVATE PNPBA_PLUGIN_ABI="${PNPBA_PLUGIN_ABI}")
  install(TARGETS ${target} LIBRARY DESTINATION ${PNPBA_PLUGIN_INSTALL_SUBDIR})
endfunction()
