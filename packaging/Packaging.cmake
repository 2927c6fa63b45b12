# Installation as a service and the Debian packages (included by the top-level CMakeLists.txt).
#   cmake --install build [--prefix P]   programs, templates, configuration, systemd unit,
#                                        client library with its CMake package
#   make package (cmake --build build --target package)   build/hpose_*.deb, hpose-dev_*.deb
# Components: runtime (hpose, hposed, templates, configuration, unit, docs) and dev (the C++
# client library, its headers, CMake package and the .proto API).

install(DIRECTORY ${PROJECT_SOURCE_DIR}/templates/
        DESTINATION ${CMAKE_INSTALL_DATADIR}/hpose/templates COMPONENT runtime
        FILES_MATCHING PATTERN "*.bt" PATTERN "*.json" PATTERN "README.md")
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${PROJECT_SOURCE_DIR}/docs/API.md
              ${PROJECT_SOURCE_DIR}/docs/INSTALL.md
        DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
install(CODE "set(HPOSE_SOURCE_DIR \"${PROJECT_SOURCE_DIR}\")
set(HPOSE_BINARY_DIR \"${PROJECT_BINARY_DIR}\")
set(HPOSE_CONF_BINDIR \"${CMAKE_INSTALL_BINDIR}\")
set(HPOSE_CONF_SYSCONFDIR \"${CMAKE_INSTALL_SYSCONFDIR}\")
set(HPOSE_CONF_DOCDIR \"${CMAKE_INSTALL_DOCDIR}\")" COMPONENT runtime)
install(SCRIPT ${CMAKE_CURRENT_LIST_DIR}/install_service_files.cmake COMPONENT runtime)

# Debian packages: one per component, dependencies of the programs found by dpkg-shlibdeps.
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME hpose)
set(CPACK_PACKAGE_VENDOR "hpose")
set(CPACK_PACKAGE_CONTACT "hpose maintainers <hpose@localhost>")
# No common summary: each package's description starts with its own synopsis line.
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
# Packages install under /usr whatever the build's prefix; the configuration goes to /etc
# (outside the prefix), so CPack stages the installation with DESTDIR.
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_INSTALL_PREFIX /usr)
set(CPACK_SET_DESTDIR ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL runtime dev)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION science)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
set(CPACK_DEBIAN_ENABLE_COMPONENT_DEPENDS ON)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME hpose)
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION
    "humanoid pose from an off-board depth camera, served over gRPC
hposed watches a floor with a depth camera (OpenNI2) and serves the pose of a humanoid
robot found by matching 3D voxel templates; hpose is its command line (estimate, record,
replay, template authoring, query). Ships the default templates, an example configuration
(/etc/hpose/hposed.yaml) and the systemd unit hposed.service.")
set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA ${PROJECT_BINARY_DIR}/packaging/conffiles)
set(CPACK_DEBIAN_DEV_PACKAGE_NAME hpose-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_DESCRIPTION
    "C++ client library of the hpose daemon (hpose::client)
Connects to hposed (plaintext, TLS, bearer token) and asks for the latest pose, streams
poses to a callback and sends depth images or clouds to estimate. Found by CMake with
find_package(hpose).")
# Headers and the static libraries need gRPC's and protobuf's development files.
set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libgrpc++-dev, libprotobuf-dev, protobuf-compiler-grpc")
file(WRITE ${PROJECT_BINARY_DIR}/packaging/conffiles "/etc/hpose/hposed.yaml\n")
include(CPack)
