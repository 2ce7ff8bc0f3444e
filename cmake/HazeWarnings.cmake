# haze_warnings: an INTERFACE target that carries the project's warning and sanitizer flags
# (after pbrt's pbrt_warnings). -Wdouble-promotion catches silent doubles in float kernels.
add_library(haze_warnings INTERFACE)
target_compile_options(haze_warnings INTERFACE -Wall -Wextra -Wdouble-promotion)
if(HAZE_WERROR)
  target_compile_options(haze_warnings INTERFACE -Werror)
endif()
# HAZE_SANITIZE: ON or "address" for AddressSanitizer and UndefinedBehaviorSanitizer, "thread"
# for ThreadSanitizer (haze::parallel_for then runs on std::threads: core/src/progress.cpp).
if(HAZE_SANITIZE STREQUAL "thread")
  set(sanitizers thread)
elseif(HAZE_SANITIZE)
  set(sanitizers address,undefined)
endif()
if(sanitizers)
  # GCC 12 reports false -Wmaybe-uninitialized through std::variant under the sanitizers.
  target_compile_options(haze_warnings INTERFACE -fsanitize=${sanitizers} -fno-omit-frame-pointer $<$<CXX_COMPILER_ID:GNU>:-Wno-maybe-uninitialized>)
  target_link_options(haze_warnings INTERFACE -fsanitize=${sanitizers})
endif()

# haze_module(NAME folder-target SOURCES ... DEPS ...): one library per top-level folder (static,
# or shared with BUILD_SHARED_LIBS; symbols hidden unless a public header declares them),
# public headers in <folder>/include, exported as haze::<name> in an export set of its own (the
# package's component <name>: find_package(haze COMPONENTS core) loads only what core needs).
function(haze_module name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC_DEPS;PRIVATE_DEPS" ${ARGN})
  add_library(haze_${name} ${ARG_SOURCES})
  add_library(haze::${name} ALIAS haze_${name})
  set_target_properties(haze_${name} PROPERTIES EXPORT_NAME ${name} OUTPUT_NAME haze_${name}
    CXX_VISIBILITY_PRESET hidden VISIBILITY_INLINES_HIDDEN ON)
  target_include_directories(haze_${name} PUBLIC
    $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
    $<INSTALL_INTERFACE:${CMAKE_INSTALL_INCLUDEDIR}>
    PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src)
  target_link_libraries(haze_${name} PUBLIC ${ARG_PUBLIC_DEPS} PRIVATE ${ARG_PRIVATE_DEPS} $<BUILD_INTERFACE:haze_warnings>)
  install(TARGETS haze_${name} EXPORT haze_${name}Targets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR})
  set_property(GLOBAL APPEND PROPERTY HAZE_COMPONENTS ${name})
  install(DIRECTORY include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR})
endfunction()
