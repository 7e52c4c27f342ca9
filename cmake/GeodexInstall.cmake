# Install rules (docs/install.md). `cmake --install build --prefix P` gives:
#   P/bin/geodex, P/bin/geodexd
#   P/include/geodex/*.h                     core's public headers and the client's (geodex_client.h)
#   P/lib/libgeodex_core.a, libgeodex_client.a and what the client links (the generated API and
#     its conversions: libgeodex_proto.a, libgeodex_api_convert.a), all position-independent
#   P/lib/cmake/geodex/                      find_package(geodex CONFIG): geodex::core, geodex::client
#   P/lib/pkgconfig/geodex.pc                pkg-config --cflags --libs geodex (the client and core)
# The CLI's internals (client/cli_*.h), the terrain library (GDAL) and the server are not installed
# as libraries: a planner links the client, which links no GDAL.
include(CMakePackageConfigHelpers)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/core/include/geodex DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.h")
install(TARGETS geodex RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})

set(GEODEX_EXPORTED geodex_core)
set(GEODEX_CONFIG_CLIENT OFF)
if(TARGET geodex_client)
  install(FILES ${PROJECT_SOURCE_DIR}/client/include/geodex/geodex_client.h
          DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/geodex)
  install(TARGETS geodexd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  list(APPEND GEODEX_EXPORTED geodex_client geodex_proto geodex_api_convert)
  set(GEODEX_CONFIG_CLIENT ON)
endif()
install(TARGETS ${GEODEX_EXPORTED} EXPORT geodexTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(GEODEX_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/geodex)
install(EXPORT geodexTargets NAMESPACE geodex:: DESTINATION ${GEODEX_CMAKE_DIR})
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/geodexConfig.cmake.in
                              ${CMAKE_CURRENT_BINARY_DIR}/geodexConfig.cmake
                              INSTALL_DESTINATION ${GEODEX_CMAKE_DIR})
write_basic_package_version_file(${CMAKE_CURRENT_BINARY_DIR}/geodexConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/geodexConfig.cmake
              ${CMAKE_CURRENT_BINARY_DIR}/geodexConfigVersion.cmake
        DESTINATION ${GEODEX_CMAKE_DIR})

# pkg-config: the client and everything it links, in link order.
file(RELATIVE_PATH GEODEX_PC_TO_PREFIX "/p/${CMAKE_INSTALL_LIBDIR}/pkgconfig" "/p")
configure_file(${PROJECT_SOURCE_DIR}/cmake/geodex.pc.in ${CMAKE_CURRENT_BINARY_DIR}/geodex.pc @ONLY)
install(FILES ${CMAKE_CURRENT_BINARY_DIR}/geodex.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig)
