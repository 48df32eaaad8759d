# Installs the command-line tools, the module libraries, their public headers and a
# relocatable CMake package: find_package(pnpba) gives pnpba::<module> for each module and
# pnpba::pnpba for all of them, and finds the packages they need itself.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

get_property(pnpba_modules GLOBAL PROPERTY PNPBA_MODULES)
set(pnpba_module_targets)
foreach(m IN LISTS pnpba_modules)
  list(APPEND pnpba_module_targets pnpba_${m})
  install(DIRECTORY ${PROJECT_SOURCE_DIR}/${m}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endforeach()

# pnpba::pnpba: every module.
add_library(pnpba_all INTERFACE)
add_library(pnpba::pnpba ALIAS pnpba_all)
set_target_properties(pnpba_all PROPERTIES EXPORT_NAME pnpba)
target_link_libraries(pnpba_all INTERFACE ${pnpba_module_targets})

install(TARGETS ${pnpba_module_targets} pnpba_all EXPORT pnpbaTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
set(pnpba_cmake_dir ${CMAKE_INSTALL_LIBDIR}/cmake/pnpba)
install(EXPORT pnpbaTargets NAMESPACE pnpba:: DESTINATION ${pnpba_cmake_dir})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/pnpbaConfig.cmake.in
  ${PROJECT_BINARY_DIR}/pnpbaConfig.cmake INSTALL_DESTINATION ${pnpba_cmake_dir})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/pnpbaConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/pnpbaConfig.cmake ${PROJECT_BINARY_DIR}/pnpbaConfigVersion.cmake
              ${PROJECT_SOURCE_DIR}/cmake/FindPnpbaOpenCV.cmake
        DESTINATION ${pnpba_cmake_dir})
