# Finds every dependency from Debian 12 packages. Each failure names the
# package that provides what is missing (scripts/install-deps.sh installs all).

macro(stentsim_require found pkg what)
  if(NOT ${found})
    message(FATAL_ERROR "stentsim: ${what} not found. Install the Debian package '${pkg}' "
                        "(or run scripts/install-deps.sh).")
  endif()
endmacro()

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

# xxHash ships no CMake config in Debian 12.
find_path(XXHASH_INCLUDE_DIR xxhash.h)
find_library(XXHASH_LIBRARY xxhash)
if(NOT XXHASH_INCLUDE_DIR OR NOT XXHASH_LIBRARY)
  stentsim_require(FALSE libxxhash-dev "xxHash")
endif()
add_library(stentsim_xxhash INTERFACE)
target_include_directories(stentsim_xxhash INTERFACE ${XXHASH_INCLUDE_DIR})
target_link_libraries(stentsim_xxhash INTERFACE ${XXHASH_LIBRARY})

# VTK: name the components, otherwise Debian's config also wants Qt5 dev packages.
find_package(VTK 9.1 QUIET COMPONENTS
  CommonCore CommonDataModel IOXML IOLegacy IOGeometry FiltersCore FiltersGeneral
  FiltersGeometry FiltersModeling FiltersExtraction FiltersSources ImagingCore IOImage)
stentsim_require(VTK_FOUND libvtk9-dev "VTK 9.1 (${VTK_NOT_FOUND_MESSAGE})")

# pugixml (SimVascular .pth/.ctgr project files).
find_package(pugixml QUIET)
stentsim_require(pugixml_FOUND libpugixml-dev "pugixml")

find_package(CGAL QUIET)
stentsim_require(CGAL_FOUND libcgal-dev "CGAL")

# gmsh ships no CMake config: header + library.
find_path(GMSH_INCLUDE_DIR gmsh.h)
find_library(GMSH_LIBRARY gmsh)
if(NOT GMSH_INCLUDE_DIR OR NOT GMSH_LIBRARY)
  stentsim_require(FALSE libgmsh-dev "gmsh C++ API")
endif()
add_library(stentsim_gmsh INTERFACE)
target_include_directories(stentsim_gmsh INTERFACE ${GMSH_INCLUDE_DIR})
target_link_libraries(stentsim_gmsh INTERFACE ${GMSH_LIBRARY})

# UMFPACK (SuiteSparse) for the sparse direct solver: its AMD ordering of the
# symmetric pattern keeps the fill of 3D finite-element matrices far below
# KLU2's (Case 1 artery, 27k DOFs: 60 s per KLU2 factorization).
find_path(UMFPACK_INCLUDE_DIR umfpack.h PATH_SUFFIXES suitesparse)
find_library(UMFPACK_LIBRARY umfpack)
if(NOT UMFPACK_INCLUDE_DIR OR NOT UMFPACK_LIBRARY)
  stentsim_require(FALSE libsuitesparse-dev "UMFPACK (SuiteSparse)")
endif()
add_library(stentsim_umfpack INTERFACE)
target_include_directories(stentsim_umfpack INTERFACE ${UMFPACK_INCLUDE_DIR})
target_link_libraries(stentsim_umfpack INTERFACE ${UMFPACK_LIBRARY})

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
