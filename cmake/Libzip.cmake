# Debian's libzip-dev ships a libzip-config.cmake whose targets reference the
# zipcmp/zipmerge tools of another package, so we find the library ourselves.
if(NOT TARGET geods_libzip)
  find_path(LIBZIP_INCLUDE_DIR zip.h REQUIRED)
  find_library(LIBZIP_LIBRARY zip REQUIRED)
  add_library(geods_libzip INTERFACE IMPORTED)
  target_include_directories(geods_libzip INTERFACE ${LIBZIP_INCLUDE_DIR})
  target_link_libraries(geods_libzip INTERFACE ${LIBZIP_LIBRARY})
endif()
