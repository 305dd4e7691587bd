# ulc::bags: the recording readers (ROS 1 bags, MCAP, rosbag2 SQLite) under include/ulc/bags.
# Header-only like the rest, but they decompress and query SQLite, so they link Debian's
#   libbz2-dev, liblz4-dev, libzstd-dev, libsqlite3-dev, and libyaml-cpp-dev for rosbag2's
#   metadata.yaml.
# Kept apart from ulc::ulc: a user who needs only the algorithms keeps its three dependencies.
find_package(BZip2 REQUIRED)
find_package(SQLite3 REQUIRED)
find_package(yaml-cpp REQUIRED)
find_package(PkgConfig REQUIRED)
pkg_check_modules(ulc_lz4 REQUIRED IMPORTED_TARGET liblz4)
pkg_check_modules(ulc_zstd REQUIRED IMPORTED_TARGET libzstd)

add_library(ulc_bags INTERFACE)
add_library(ulc::bags ALIAS ulc_bags)
set_target_properties(ulc_bags PROPERTIES EXPORT_NAME bags)
target_link_libraries(ulc_bags INTERFACE ulc::ulc BZip2::BZip2 SQLite::SQLite3 PkgConfig::ulc_lz4
                                         PkgConfig::ulc_zstd yaml-cpp)
