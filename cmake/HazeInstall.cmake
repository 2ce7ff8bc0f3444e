# install(): exported targets haze::core, haze::simd, ... (one export set per component) and a
# hazeConfig.cmake with a version file, so a consumer writes find_package(haze [COMPONENTS ...])
# and links haze::core (tests/install checks this).
include(CMakePackageConfigHelpers)
set(HAZE_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/haze)
get_property(HAZE_COMPONENTS GLOBAL PROPERTY HAZE_COMPONENTS)
foreach(component ${HAZE_COMPONENTS})
  install(EXPORT haze_${component}Targets NAMESPACE haze:: DESTINATION ${HAZE_CMAKE_DIR})
endforeach()
configure_package_config_file(cmake/hazeConfig.cmake.in ${CMAKE_CURRENT_BINARY_DIR}/hazeConfig.cmake
  INSTALL_DESTINATION ${HAZE_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/hazeConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/hazeConfig.cmake ${CMAKE_CURRENT_BINARY_DIR}/hazeConfigVersion.cmake
  DESTINATION ${HAZE_CMAKE_DIR})
