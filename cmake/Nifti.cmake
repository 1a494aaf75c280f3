# Debian's libnifti2-dev ships a NIFTIConfig.cmake whose imported paths point at
# /usr/lib instead of the multiarch directory, so we find the libraries ourselves.
if(NOT TARGET geods_nifti)
  find_path(NIFTI_INCLUDE_DIR nifti1_io.h PATH_SUFFIXES nifti REQUIRED)
  find_library(NIFTI_IO_LIBRARY niftiio REQUIRED)
  find_library(NIFTI_ZNZ_LIBRARY znz REQUIRED)
  find_package(ZLIB REQUIRED)
  add_library(geods_nifti INTERFACE IMPORTED)
  target_include_directories(geods_nifti INTERFACE ${NIFTI_INCLUDE_DIR})
  target_link_libraries(geods_nifti INTERFACE ${NIFTI_IO_LIBRARY} ${NIFTI_ZNZ_LIBRARY} ZLIB::ZLIB m)
endif()
