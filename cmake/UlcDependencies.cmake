# The library's three dependencies, all from Debian 12 packages:
#   libeigen3-dev (3.4), libtbb-dev (oneTBB 2021), libnanoflann-dev (1.4.3; 1.5+ works too).
find_package(Eigen3 3.4 REQUIRED NO_MODULE)
find_package(TBB REQUIRED)
find_package(nanoflann REQUIRED)
