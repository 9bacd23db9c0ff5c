# Third-party libraries, all from Debian 12 packages (see README.md).

find_package(Eigen3 3.3 CONFIG REQUIRED)
find_package(Threads REQUIRED)

# OCCT: asking for COMPONENTS fails in Debian's config, so take the plain targets.
find_package(OpenCASCADE CONFIG REQUIRED)
add_library(bvmesh_occt INTERFACE)
target_include_directories(bvmesh_occt SYSTEM INTERFACE ${OpenCASCADE_INCLUDE_DIR})
target_link_libraries(bvmesh_occt INTERFACE
  TKSTEP TKIGES TKXSBase TKShHealing TKOffset TKBool TKBO TKPrim TKMesh
  TKTopAlgo TKGeomAlgo TKBRep TKGeomBase TKG3d TKG2d TKMath TKernel)

# OpenSubdiv: Debian's OpenSubdivConfig names static libraries that are not shipped,
# so locate the header and the CPU library directly.
find_path(OPENSUBDIV_INCLUDE_DIR opensubdiv/far/topologyRefiner.h REQUIRED)
find_library(OPENSUBDIV_CPU_LIBRARY NAMES osdCPU REQUIRED)
add_library(bvmesh_opensubdiv INTERFACE)
target_include_directories(bvmesh_opensubdiv SYSTEM INTERFACE ${OPENSUBDIV_INCLUDE_DIR})
target_link_libraries(bvmesh_opensubdiv INTERFACE ${OPENSUBDIV_CPU_LIBRARY})

# SuiteSparse: CHOLMOD's supernodal sparse Cholesky for the least-squares normal equations
# (Eigen's own simplicial factorization is an order of magnitude slower on fitting-sized meshes),
# and UMFPACK's sparse LU for the hyperbolic marching's steps (one factor preconditions many
# solves, and UMFPACK's are faster than Eigen's SparseLU's: docs/volume.md).
find_path(CHOLMOD_INCLUDE_DIR cholmod.h PATH_SUFFIXES suitesparse REQUIRED)
find_library(CHOLMOD_LIBRARY NAMES cholmod REQUIRED)
find_library(UMFPACK_LIBRARY NAMES umfpack REQUIRED)
add_library(bvmesh_suitesparse INTERFACE)
target_include_directories(bvmesh_suitesparse SYSTEM INTERFACE ${CHOLMOD_INCLUDE_DIR})
target_link_libraries(bvmesh_suitesparse INTERFACE ${CHOLMOD_LIBRARY} ${UMFPACK_LIBRARY})

# CGNS (Debian's libcgns-dev, HDF5 backend): no CMake or pkg-config file, so locate it directly.
# The CGNS writer keeps it private to the core.
find_path(CGNS_INCLUDE_DIR cgnslib.h REQUIRED)
find_library(CGNS_LIBRARY NAMES cgns REQUIRED)
add_library(bvmesh_cgns INTERFACE)
target_include_directories(bvmesh_cgns SYSTEM INTERFACE ${CGNS_INCLUDE_DIR})
target_link_libraries(bvmesh_cgns INTERFACE ${CGNS_LIBRARY})

if(BVMESH_BUILD_PYTHON)
  find_package(Python 3.9 REQUIRED COMPONENTS Interpreter Development.Module)
  find_package(pybind11 CONFIG REQUIRED)
endif()
if(BVMESH_BUILD_TESTS)
  find_package(GTest CONFIG REQUIRED)
  include(GoogleTest)
endif()
