# bounce_warnings(target): the project's warning set, as errors when BOUNCE_WERROR is on.
function(bounce_warnings target)
  get_target_property(type ${target} TYPE)
  if(type STREQUAL "INTERFACE_LIBRARY")
    return()
  endif()
  target_compile_options(${target} PRIVATE -Wall -Wextra -Wpedantic $<$<BOOL:${BOUNCE_WERROR}>:-Werror>)
endfunction()

# bounce_adapter(name ...): an adapter library bounce::<name> with headers in
# adapters/<name>/include, installed and exported.
function(bounce_adapter name)
  cmake_parse_arguments(A "" "" "SOURCES;PUBLIC_LIBS;PRIVATE_LIBS" ${ARGN})
  if(A_SOURCES)
    add_library(bounce_${name} STATIC ${A_SOURCES})
    target_include_directories(bounce_${name} PUBLIC
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(bounce_${name} PUBLIC bounce::bounce ${A_PUBLIC_LIBS} PRIVATE ${A_PRIVATE_LIBS})
    set_target_properties(bounce_${name} PROPERTIES POSITION_INDEPENDENT_CODE ON)
    bounce_warnings(bounce_${name})
  else()
    add_library(bounce_${name} INTERFACE)
    target_include_directories(bounce_${name} INTERFACE
      $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
      $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>)
    target_link_libraries(bounce_${name} INTERFACE bounce::bounce ${A_PUBLIC_LIBS})
  endif()
  set_target_properties(bounce_${name} PROPERTIES EXPORT_NAME ${name})
  add_library(bounce::${name} ALIAS bounce_${name})
  # One export file per component, so find_package(bounce COMPONENTS gl embree) reads (and
  # finds the dependencies of) only what the consumer asked for.
  install(TARGETS bounce_${name} EXPORT bounce_${name}Targets)
  install(EXPORT bounce_${name}Targets NAMESPACE bounce:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/bounce)
  install(DIRECTORY include/bounce DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
  set_property(GLOBAL APPEND PROPERTY BOUNCE_COMPONENTS ${name})
endfunction()
