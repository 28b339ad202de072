# Install rules and the Debian package (CPack DEB). `cmake --install` lays out what a board needs:
#   /usr/bin/loomctl (+ the technician's and builder's tools built in this tree)
#   /etc/loomctl/loom.toml                   the embedded default loom, as a conffile (upgrades keep edits)
#   /lib/systemd/system/loomctl.service      runs `loomctl serve`; /etc/default/loomctl its arguments
#   /usr/share/loomctl/lcmtypes/*.lcm        the telemetry's LCM types (for lcm-gen, lcm-spy)
# `tools/loom package` runs cpack for the host (amd64) and the arm64 cross build.
include(GNUInstallDirs)

set(LOOM_PACKAGED_PROGRAMS loomctl loom-monitor loom-plot loom-sim-drive loom-kin loom-synth loom-dynamics loom-profile)
foreach(t ${LOOM_PACKAGED_PROGRAMS})
  if(TARGET ${t})
    install(TARGETS ${t} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT loomctl)
  endif()
endforeach()

set(pkg ${CMAKE_CURRENT_LIST_DIR})
install(FILES ${PROJECT_SOURCE_DIR}/firmware/config/default_loom.toml DESTINATION /etc/loomctl RENAME loom.toml
        COMPONENT loomctl)
install(FILES ${pkg}/loomctl.default DESTINATION /etc/default RENAME loomctl COMPONENT loomctl)
install(FILES ${pkg}/loomctl.service DESTINATION /lib/systemd/system COMPONENT loomctl)
file(GLOB LOOM_LCM_FILES ${PROJECT_SOURCE_DIR}/firmware/telemetry/lcmtypes/*.lcm)
install(FILES ${LOOM_LCM_FILES} DESTINATION ${CMAKE_INSTALL_DATADIR}/loomctl/lcmtypes COMPONENT loomctl)
install(FILES ${PROJECT_SOURCE_DIR}/README.md DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT loomctl)

# ---- CPack: one .deb per architecture, named loomctl_<version>_<arch>.deb ----
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(LOOM_DEB_ARCH arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(LOOM_DEB_ARCH amd64)
else()
  set(LOOM_DEB_ARCH ${CMAKE_SYSTEM_PROCESSOR})
endif()
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME loomctl)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "loomctl maintainers <loomctl@localhost>")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "controller for a mechanised handmade-carpet loom")
set(CPACK_PACKAGE_DESCRIPTION "loomctl drives the shedding, picking, beat-up and carriage mechanisms of a
mechanised handmade-carpet loom over CANopen (SocketCAN), or a simulated loom, in a fixed-rate real-time
loop. The loomctl service arms the loom and waits for the operator's commands (loomctl ctl, the I/O
node's buttons); telemetry is published over LCM.")
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${LOOM_DEB_ARCH})
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_STRIP_FILES ON)
# Runtime dependencies by Debian name (tests/board/package_test.sh checks that every library the
# binaries load comes from one of these): the C++ runtime, LCM, toml++, NLopt (loom-dynamics' balancing)
# and Google Benchmark (loom-profile's lookup timings). Names are the same on amd64 and arm64.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, liblcm1 (>= 1.3.1), libtomlplusplus3 (>= 3.3.0), libnlopt0 (>= 2.7.1), libbenchmark1debian (>= 1.7.1), libpng16-16 (>= 1.6.39)")
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "can-utils, iproute2")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "rt-tests, liblcm-bin")
configure_file(${pkg}/postinst ${CMAKE_BINARY_DIR}/packaging/postinst COPYONLY)
configure_file(${pkg}/conffiles ${CMAKE_BINARY_DIR}/packaging/conffiles COPYONLY)
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA "${CMAKE_BINARY_DIR}/packaging/postinst;${CMAKE_BINARY_DIR}/packaging/conffiles")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR}/packages)
include(CPack)
