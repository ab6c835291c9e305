# Language standard, warnings and the helper that compiles Trilinos adapters.
set(CMAKE_CXX_STANDARD 20)
set(CMAKE_CXX_STANDARD_REQUIRED ON)
set(CMAKE_CXX_EXTENSIONS OFF)
set(CMAKE_POSITION_INDEPENDENT_CODE ON)
set(CMAKE_EXPORT_COMPILE_COMMANDS ON)

add_compile_options(-Wall -Wextra -Wno-unused-parameter)
# GCC 12 at -O3 reports false -Wrestrict overlaps inside std::string
# concatenation (GCC bug 105329); the warning says nothing about our code.
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  add_compile_options(-Wno-restrict)
endif()

# Trilinos 13.2's Teuchos headers do not compile as C++20 with GCC 12
# (a template-id constructor in Teuchos_StandardParameterEntryValidators.hpp).
# The few adapter files that include Trilinos are compiled as C++17; no public
# header of the project includes Trilinos, so the rest stays C++20.
function(stentsim_compile_as_cxx17)
  foreach(src IN LISTS ARGN)
    set_source_files_properties(${src} PROPERTIES COMPILE_OPTIONS "-std=c++17;-Wno-deprecated-declarations")
  endforeach()
endfunction()

# Every project library is added through this so that includes resolve from
# the source root (#include "pipeline/runner.hpp").
function(stentsim_library name)
  cmake_parse_arguments(ARG "" "" "SOURCES;PUBLIC;PRIVATE" ${ARGN})
  add_library(${name} STATIC ${ARG_SOURCES})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR})
  target_link_libraries(${name} PUBLIC ${ARG_PUBLIC} PRIVATE ${ARG_PRIVATE})
endfunction()
