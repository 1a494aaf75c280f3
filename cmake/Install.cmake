include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(TARGETS geods EXPORT geodsTargets
        ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR}
        LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR}
        INCLUDES DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
install(DIRECTORY include/geods DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
if(TARGET geods_cli)
  install(TARGETS geods_cli RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR})
  install(FILES ${PROJECT_BINARY_DIR}/share/geods.1 DESTINATION ${CMAKE_INSTALL_MANDIR}/man1)
  install(FILES ${PROJECT_BINARY_DIR}/share/geods.bash DESTINATION ${CMAKE_INSTALL_DATADIR}/bash-completion/completions
          RENAME geods)
endif()
# The Python package (extension, *.py, type stubs) into GEODS_PYTHON_INSTALL_DIR.
if(TARGET _geods)
  install(TARGETS _geods LIBRARY DESTINATION ${GEODS_PYTHON_INSTALL_DIR}/geods)
  install(FILES ${GEODS_PYTHON_FILES} DESTINATION ${GEODS_PYTHON_INSTALL_DIR}/geods)
endif()

set(GEODS_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/geods)
install(EXPORT geodsTargets NAMESPACE geods:: DESTINATION ${GEODS_CMAKE_DIR})
configure_package_config_file(cmake/geodsConfig.cmake.in
  ${PROJECT_BINARY_DIR}/geodsConfig.cmake INSTALL_DESTINATION ${GEODS_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/geodsConfigVersion.cmake
  COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/geodsConfig.cmake ${PROJECT_BINARY_DIR}/geodsConfigVersion.cmake
              cmake/Nifti.cmake cmake/Libzip.cmake
        DESTINATION ${GEODS_CMAKE_DIR})
