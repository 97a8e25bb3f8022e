# SPDX-License-Identifier: GPL-2.0-or-later
# cmake/Modules/Packages/SEDIMENT.cmake of a LAMMPS tree: the SEDIMENT package's needs beyond its
# sources (installed by lammps-pkg/install-in-tree.sh). fix layers/hdf5 writes HDF5 (serial
# interface, rank 0 only); the physics core's headers sit in src/SEDIMENT/sediment/.
enable_language(C)
# fix fluid/flow solves the flow with KSPACE's distributed FFT (fft3d_wrap.h): the package needs it,
# in double precision (the style passes doubles), best over FFTW3 (-D FFT=FFTW3).
if(NOT PKG_KSPACE)
  message(FATAL_ERROR "SEDIMENT needs the KSPACE package (fix fluid/flow uses its FFTs): add -D PKG_KSPACE=on "
                      "(with -D FFT=FFTW3 for FFTW)")
endif()
if(FFT_SINGLE)
  message(FATAL_ERROR "SEDIMENT needs KSPACE's FFTs in double precision: -D FFT_SINGLE=off")
endif()
# The styles and the physics core are C++17 (std::optional, std::string_view, std::clamp). A tree may set
# less for itself (LAMMPS 29 Sep 2021, Debian 12's, sets CMAKE_CXX_STANDARD 11 unconditionally, so
# -D CMAKE_CXX_STANDARD=17 is ignored): ask for C++17 on the target, which raises the standard where
# the tree's is lower and leaves a higher one as it is.
target_compile_features(lammps PUBLIC cxx_std_17)
set(HDF5_PREFER_PARALLEL FALSE)
find_package(HDF5 COMPONENTS C REQUIRED)
if((NOT BUILD_MPI) AND HDF5_IS_PARALLEL)
  message(FATAL_ERROR "SEDIMENT: a serial LAMMPS build cannot use a parallel HDF5 library")
endif()
target_link_libraries(lammps PRIVATE ${HDF5_LIBRARIES})
target_include_directories(lammps PRIVATE ${HDF5_INCLUDE_DIRS} ${LAMMPS_SOURCE_DIR}/SEDIMENT)
# No errno from sqrt and friends in the package's own sources (nothing reads it): the per-sphere
# loops of the drag step then compile to vector square roots. No fused multiply-adds: every kind of
# the drag step's vector arithmetic (SSE2, AVX2, AVX-512) rounds each operation alike.
if(CMAKE_CXX_COMPILER_ID MATCHES "GNU|Clang")
  file(GLOB SEDIMENT_PACKAGE_SOURCES ${LAMMPS_SOURCE_DIR}/SEDIMENT/*.cpp)
  set_property(SOURCE ${SEDIMENT_PACKAGE_SOURCES} APPEND PROPERTY COMPILE_OPTIONS -fno-math-errno -ffp-contract=off)
endif()
