# Debian 12's OpenImageIO 2.4 package config lists /usr/include/opencv4 among the include
# folders of OpenImageIO::OpenImageIO (OIIO was built with OpenCV) although
# libopenimageio-dev does not depend on libopencv-dev; CMake then refuses to generate any
# target linking it ("includes non-existent path"). Dropping the folders that do not exist
# changes nothing else: the OIIO headers bounce includes do not include OpenCV.
# Included by adapters/io/CMakeLists.txt and by the installed bounceConfig.cmake.
if(TARGET OpenImageIO::OpenImageIO)
  foreach(_bounce_prop INTERFACE_INCLUDE_DIRECTORIES INTERFACE_SYSTEM_INCLUDE_DIRECTORIES)
    get_target_property(_bounce_dirs OpenImageIO::OpenImageIO ${_bounce_prop})
    if(_bounce_dirs)
      set(_bounce_kept "")
      foreach(_bounce_dir IN LISTS _bounce_dirs)
        if(_bounce_dir MATCHES "^\\$<" OR EXISTS "${_bounce_dir}")
          list(APPEND _bounce_kept "${_bounce_dir}")
        endif()
      endforeach()
      set_property(TARGET OpenImageIO::OpenImageIO PROPERTY ${_bounce_prop} "${_bounce_kept}")
    endif()
  endforeach()
  unset(_bounce_prop)
  unset(_bounce_dirs)
  unset(_bounce_kept)
  unset(_bounce_dir)
endif()
