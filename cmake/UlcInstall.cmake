# install() rules and an exported package, so a consumer can write
#   find_package(ulc CONFIG REQUIRED)
#   target_link_libraries(app PRIVATE ulc::ulc)
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/ DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        FILES_MATCHING PATTERN "*.hpp")
install(TARGETS ulc ulc_calibrate EXPORT ulcTargets ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR})
install(EXPORT ulcTargets NAMESPACE ulc:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ulc)
# The recording readers are a component of their own, so that find_package(ulc) alone needs only
# the three core dependencies: find_package(ulc CONFIG REQUIRED COMPONENTS bags) -> ulc::bags.
install(TARGETS ulc_bags EXPORT ulcBagsTargets)
install(EXPORT ulcBagsTargets NAMESPACE ulc:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ulc)
# The same for ULC's own files (result file, ground_truth.json, YAML result): COMPONENTS results
# -> ulc::results, with nlohmann_json and yaml-cpp.
install(TARGETS ulc_results EXPORT ulcResultsTargets)
install(EXPORT ulcResultsTargets NAMESPACE ulc:: DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ulc)

configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/ulcConfig.cmake.in
                              ${PROJECT_BINARY_DIR}/ulcConfig.cmake
                              INSTALL_DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ulc)
# Header-only: the version file must not check the consumer's pointer size.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/ulcConfigVersion.cmake
                                 VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion
                                 ARCH_INDEPENDENT)
install(FILES ${PROJECT_BINARY_DIR}/ulcConfig.cmake ${PROJECT_BINARY_DIR}/ulcConfigVersion.cmake
        DESTINATION ${CMAKE_INSTALL_LIBDIR}/cmake/ulc)
