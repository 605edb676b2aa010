# Third-party packages, all from Debian (deploy/install-deps.sh). Includes are SYSTEM so their
# warnings never show up as ours.
find_package(Threads REQUIRED)
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(spdlog REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(nlohmann_json 3.10 REQUIRED)
find_package(CLI11 REQUIRED)
find_package(OpenMP REQUIRED COMPONENTS CXX)
find_package(Protobuf REQUIRED)
find_package(gRPC CONFIG REQUIRED)
find_package(CURL REQUIRED)
# cpp-httplib: the server's HTTP side (/metrics, /healthz, /debug/calls). Debian builds it as a
# shared library with OpenSSL, zlib and Brotli support; its pkg-config file carries the matching
# definitions, which the header's class layouts depend on.
find_package(PkgConfig REQUIRED)
pkg_check_modules(HTTPLIB REQUIRED IMPORTED_TARGET cpp-httplib)
if(TUBEPICK_BUILD_TESTS)
  find_package(GTest REQUIRED)
endif()
if(TUBEPICK_BUILD_BENCHMARKS)
  find_package(benchmark REQUIRED)
endif()

# PCL: only the components core/ uses (pcl/point_cloud.h and pcl/kdtree/kdtree_flann.h in
# core/modeling/filter_outliers.cc; every other stage is our own code), wrapped in one interface
# target with SYSTEM includes. Debian's VTK (pulled in by PCLConfig) links MPI::MPI_C; define it first.
find_package(MPI QUIET COMPONENTS C)
find_package(PCL 1.12 REQUIRED COMPONENTS common kdtree)
add_library(tubepick_pcl INTERFACE)
target_include_directories(tubepick_pcl SYSTEM INTERFACE ${PCL_INCLUDE_DIRS})
# Only the component libraries (PCL_LIBRARIES also drags in VTK, which core never uses).
target_link_libraries(tubepick_pcl INTERFACE ${PCL_COMMON_LIBRARIES} ${PCL_KDTREE_LIBRARIES} FLANN::FLANN)
target_compile_definitions(tubepick_pcl INTERFACE ${PCL_DEFINITIONS})

# Bullet in double precision everywhere (Debian's BulletConfig-float64.cmake): the definition is
# propagated PUBLIC so every file that sees btScalar sees the same one.
set(_bullet_cfg /usr/lib/x86_64-linux-gnu/cmake/bullet/BulletConfig-float64.cmake)
if(NOT EXISTS ${_bullet_cfg})
  message(FATAL_ERROR "Bullet double precision not found (${_bullet_cfg}); run deploy/install-deps.sh")
endif()
include(${_bullet_cfg})
add_library(tubepick_bullet INTERFACE)
target_include_directories(tubepick_bullet SYSTEM INTERFACE ${BULLET_ROOT_DIR}/${BULLET_INCLUDE_DIR})
target_link_directories(tubepick_bullet INTERFACE ${BULLET_ROOT_DIR}/${BULLET_LIBRARY_DIRS})
target_link_libraries(tubepick_bullet INTERFACE BulletDynamics-float64 BulletCollision-float64 LinearMath-float64)
target_compile_definitions(tubepick_bullet INTERFACE BT_USE_DOUBLE_PRECISION)
