# Debian's orocos_kdl-config.cmake defines variables, not a target; wrap it in an imported target.
if(NOT TARGET orocos_kdl::orocos_kdl)
  find_package(orocos_kdl CONFIG REQUIRED)
  find_library(VERESHCHAGIN_KDL_LIBRARY NAMES orocos-kdl HINTS ${orocos_kdl_LIBRARY_DIRS})
  find_path(VERESHCHAGIN_KDL_INCLUDE_DIR kdl/chain.hpp HINTS ${orocos_kdl_INCLUDE_DIRS})
  if(NOT VERESHCHAGIN_KDL_LIBRARY OR NOT VERESHCHAGIN_KDL_INCLUDE_DIR)
    message(FATAL_ERROR "Orocos KDL not found (apt-get install liborocos-kdl-dev)")
  endif()
  add_library(orocos_kdl::orocos_kdl UNKNOWN IMPORTED)
  set_target_properties(orocos_kdl::orocos_kdl PROPERTIES
    IMPORTED_LOCATION "${VERESHCHAGIN_KDL_LIBRARY}"
    INTERFACE_INCLUDE_DIRECTORIES "${VERESHCHAGIN_KDL_INCLUDE_DIR}")
endif()
