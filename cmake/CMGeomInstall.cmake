# install() rules and the package configuration that lets another project call find_package(CMGeom).
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/CMGeom DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
set(_cmgeom_export_targets CMGeom CMGeom_Mesh_IO CMGeom_Image_IO CMGeom_Textured_simplification CMGeom_Compact_model)
if(TARGET CMGeom_OSMesa)
  list(APPEND _cmgeom_export_targets CMGeom_OSMesa)
endif()
install(TARGETS ${_cmgeom_export_targets} EXPORT CMGeomTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(TARGETS cmgeom_image_io_oiio LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmgeom)
install(EXPORT CMGeomTargets NAMESPACE CMGeom:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/CMGeom)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/CMGeomConfig.cmake.in
  ${CMAKE_BINARY_DIR}/CMGeomConfig.cmake INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/CMGeom)
write_basic_package_version_file(${CMAKE_BINARY_DIR}/CMGeomConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMinorVersion)
install(FILES ${CMAKE_BINARY_DIR}/CMGeomConfig.cmake ${CMAKE_BINARY_DIR}/CMGeomConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/CMGeom)
# The bundled default model (with its license), which `cmgeom pipeline` runs on when no model is given.
install(DIRECTORY ${PROJECT_SOURCE_DIR}/data/ DESTINATION ${CMAKE_INSTALL_DATADIR}/CMGeom/data)
