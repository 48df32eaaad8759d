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
