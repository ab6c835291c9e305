# Finds every dependency from Debian 12 packages. Each failure names the
# package that provides what is missing (scripts/install-deps.sh installs all).

macro(stentsim_require found pkg what)
  if(NOT ${found})
    message(FATAL_ERROR "stentsim: ${what} not found. Install the Debian package '${pkg}' "
                        "(or run scripts/install-deps.sh).")
  endif()
endmacro()

# A library that ships no CMake config: header + library found by name, and an
# INTERFACE target `target` carrying both. Extra arguments go to find_path
# (e.g. PATH_SUFFIXES suitesparse).
function(stentsim_plain_library target header lib pkg what)
  string(MAKE_C_IDENTIFIER "${target}" id)
  find_path(${id}_INCLUDE_DIR ${header} ${ARGN})
  find_library(${id}_LIBRARY ${lib})
  if(NOT ${id}_INCLUDE_DIR OR NOT ${id}_LIBRARY)
    stentsim_require(FALSE "${pkg}" "${what}")
  endif()
  add_library(${target} INTERFACE)
  target_include_directories(${target} INTERFACE ${${id}_INCLUDE_DIR})
  target_link_libraries(${target} INTERFACE ${${id}_LIBRARY})
endfunction()

find_package(MPI QUIET COMPONENTS C CXX)
stentsim_require(MPI_CXX_FOUND "libopenmpi-dev openmpi-bin" "MPI (C++)")

find_package(Eigen3 3.4 QUIET NO_MODULE)
stentsim_require(Eigen3_FOUND libeigen3-dev "Eigen 3.4")

find_package(yaml-cpp QUIET)
stentsim_require(yaml-cpp_FOUND libyaml-cpp-dev "yaml-cpp")

find_package(fmt QUIET)
stentsim_require(fmt_FOUND libfmt-dev "fmt")

find_package(CLI11 QUIET)
stentsim_require(CLI11_FOUND libcli11-dev "CLI11")

find_package(Threads REQUIRED)

# oneTBB: the solver's threaded element loops (solver/assembly/threads.cpp).
find_package(TBB QUIET)
stentsim_require(TBB_FOUND libtbb-dev "oneTBB")

# xxHash ships no CMake config in Debian 12.
stentsim_plain_library(stentsim_xxhash xxhash.h xxhash libxxhash-dev "xxHash")

# VTK: name the components, otherwise Debian's config also wants Qt5 dev packages.
find_package(VTK 9.1 QUIET COMPONENTS
  CommonCore CommonDataModel IOXML IOLegacy IOGeometry FiltersCore FiltersGeneral
  FiltersGeometry FiltersModeling FiltersExtraction FiltersSources ImagingCore IOImage)
stentsim_require(VTK_FOUND libvtk9-dev "VTK 9.1 (${VTK_NOT_FOUND_MESSAGE})")

# pugixml (SimVascular .pth/.ctgr project files).
find_package(pugixml QUIET)
stentsim_require(pugixml_FOUND libpugixml-dev "pugixml")

# zlib: NIfTI .nii.gz headers and sizes are checked before VTK reads them.
find_package(ZLIB QUIET)
stentsim_require(ZLIB_FOUND zlib1g-dev "zlib")

find_package(CGAL QUIET)
stentsim_require(CGAL_FOUND libcgal-dev "CGAL")

# gmsh ships no CMake config: header + library.
stentsim_plain_library(stentsim_gmsh gmsh.h gmsh libgmsh-dev "gmsh C++ API")

# UMFPACK (SuiteSparse) for the sparse direct solver: its AMD ordering of the
# symmetric pattern keeps the fill of 3D finite-element matrices far below
# KLU2's (Case 1 artery, 27k DOFs: 60 s per KLU2 factorization).
stentsim_plain_library(stentsim_umfpack umfpack.h umfpack libsuitesparse-dev "UMFPACK (SuiteSparse)" PATH_SUFFIXES suitesparse)

# PLplot (C API) for headless PNG/SVG figures; the cairo devices come from
# plplot-driver-cairo (checked at run time, the driver is a plugin).
find_package(PkgConfig QUIET)
if(PkgConfig_FOUND)
  pkg_check_modules(PLPLOT QUIET IMPORTED_TARGET plplot)
endif()
stentsim_require(PLPLOT_FOUND "libplplot-dev plplot-driver-cairo" "PLplot (pkg-config plplot)")
add_library(stentsim_plplot INTERFACE)
target_link_libraries(stentsim_plplot INTERFACE PkgConfig::PLPLOT)

# Trilinos 13.2. Debian's config can report "found" while a component's
# library list is empty: check each one.
set(STENTSIM_TRILINOS_COMPONENTS Tpetra Belos Ifpack2 MueLu Amesos2 Teuchos)
find_package(Trilinos QUIET COMPONENTS ${STENTSIM_TRILINOS_COMPONENTS})
stentsim_require(Trilinos_FOUND trilinos-all-dev "Trilinos (with Tpetra, Belos, Ifpack2, MueLu, Amesos2, Teuchos)")
foreach(comp IN LISTS STENTSIM_TRILINOS_COMPONENTS)
  if(NOT "${comp}" IN_LIST Trilinos_PACKAGE_LIST OR "${${comp}_LIBRARIES}" STREQUAL "")
    message(FATAL_ERROR "stentsim: Trilinos component '${comp}' is missing or has no libraries. "
                        "Install the Debian package 'trilinos-all-dev' and its TPL dev packages "
                        "(libptscotch-dev libscotch-dev libmumps-dev libhdf5-openmpi-dev "
                        "liblapack-dev libblas-dev zlib1g-dev), or run scripts/install-deps.sh.")
  endif()
endforeach()
add_library(stentsim_trilinos INTERFACE)
target_include_directories(stentsim_trilinos SYSTEM INTERFACE ${Trilinos_INCLUDE_DIRS} ${Trilinos_TPL_INCLUDE_DIRS})
target_link_libraries(stentsim_trilinos INTERFACE ${Trilinos_LIBRARIES} ${Trilinos_TPL_LIBRARIES} MPI::MPI_CXX)

find_package(GTest QUIET)
if(STENTSIM_BUILD_TESTS)
  stentsim_require(GTest_FOUND "libgtest-dev libgmock-dev" "GoogleTest")
endif()

message(STATUS "stentsim: Trilinos ${Trilinos_VERSION}, VTK ${VTK_VERSION}, CGAL ${CGAL_VERSION}, "
               "Eigen ${Eigen3_VERSION}, yaml-cpp ${yaml-cpp_VERSION}, MPI ${MPI_CXX_VERSION}")
