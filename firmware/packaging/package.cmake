# Install rules and the Debian package (CPack DEB). `cmake --install` lays out what a board needs:
#   /usr/bin/loomctl, loom-panel, loom-spy (+ the technician's and builder's tools built in this tree)
#   /usr/share/loomctl/loomlcm.jar          the telemetry's LCM types for Java (loom-spy; a private jar)
#   /etc/loomctl/loom.toml                   the embedded default loom, as a conffile (upgrades keep edits)
#   /lib/systemd/system/loomctl.service      runs `loomctl serve`; /etc/default/loomctl its arguments
#   /lib/systemd/system/loom-panel.service   the web panel (not enabled); /etc/default/loom-panel
#   /usr/share/loomctl/lcmtypes/*.lcm        the telemetry's LCM types (for lcm-gen, lcm-spy)
#   /usr/share/man/man1/*.1.gz               a manual page per program (help2man from --help)
#   /usr/share/doc/loomctl/                  README.md, copyright, changelog.gz
# `tools/loom package` runs cpack for the host (amd64) and the arm64 cross build.
include(GNUInstallDirs)

set(LOOM_PACKAGED_PROGRAMS loomctl loom-monitor loom-plot loom-sim-drive loom-kin loom-synth loom-dynamics loom-profile
    loom-panel)
# One line per program for its manual page's NAME section.
set(LOOM_MAN_loomctl "controller for a mechanised handmade-carpet loom (serve, ctl, weave, check, commission)")
set(LOOM_MAN_loom-monitor "print a loom's LCM telemetry as text")
set(LOOM_MAN_loom-plot "plots of a loomctl run report")
set(LOOM_MAN_loom-sim-drive "simulated CiA 402 servo drives on a CAN interface")
set(LOOM_MAN_loom-kin "kinematics of the loom's linkages as CSV")
set(LOOM_MAN_loom-synth "dimensional synthesis of the beat-up linkage")
set(LOOM_MAN_loom-dynamics "beat-up forces, crank speed and shaking balance of the loom's linkages")
set(LOOM_MAN_loom-profile "motion-profile table accuracy against lookup time")
set(LOOM_MAN_loom-panel "live web page of every loom's LCM telemetry")

set(pkg ${CMAKE_CURRENT_LIST_DIR})
set(man_out ${CMAKE_BINARY_DIR}/packaging/man)
find_program(LOOM_HELP2MAN help2man)
find_program(LOOM_GZIP gzip REQUIRED)
set(LOOM_MAN_PAGES)
foreach(t ${LOOM_PACKAGED_PROGRAMS})
  if(NOT TARGET ${t})
    continue()
  endif()
  install(TARGETS ${t} RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT loomctl)
  if(LOOM_HELP2MAN AND NOT CMAKE_CROSSCOMPILING)
    # From the program's own --help, so the page cannot drift from the options.
    add_custom_command(
      OUTPUT ${man_out}/${t}.1.gz
      COMMAND ${CMAKE_COMMAND} -E make_directory ${man_out}
      COMMAND ${LOOM_HELP2MAN} --no-info --no-discard-stderr --version-string=${PROJECT_VERSION}
              --name=${LOOM_MAN_${t}} --section=1 --output=${man_out}/${t}.1 $<TARGET_FILE:${t}>
      COMMAND ${LOOM_GZIP} -9nf ${man_out}/${t}.1
      DEPENDS ${t}
      COMMENT "help2man: ${t}.1"
      VERBATIM)
    list(APPEND LOOM_MAN_PAGES ${man_out}/${t}.1.gz)
  endif()
endforeach()
if(NOT LOOM_HELP2MAN)
  message(STATUS "packaging: help2man not found (apt install help2man): the .deb gets no manual pages")
endif()

# loom-spy (a script) and the jar it needs, when the Java side was built (firmware/telemetry, tools/spy).
get_property(LOOM_TYPES_JAR_FILE GLOBAL PROPERTY LOOM_TYPES_JAR)
if(TARGET loom-spy AND LOOM_TYPES_JAR_FILE)
  install(PROGRAMS ${CMAKE_RUNTIME_OUTPUT_DIRECTORY}/loom-spy DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT loomctl)
  install(FILES ${LOOM_TYPES_JAR_FILE} DESTINATION ${CMAKE_INSTALL_DATADIR}/loomctl COMPONENT loomctl)
  add_custom_command(OUTPUT ${man_out}/loom-spy.1.gz
                     COMMAND ${CMAKE_COMMAND} -E make_directory ${man_out}
                     COMMAND ${CMAKE_COMMAND} -E copy ${pkg}/loom-spy.1 ${man_out}/loom-spy.1
                     COMMAND ${LOOM_GZIP} -9nf ${man_out}/loom-spy.1
                     DEPENDS ${pkg}/loom-spy.1 VERBATIM)
  list(APPEND LOOM_MAN_PAGES ${man_out}/loom-spy.1.gz)
endif()
add_custom_command(OUTPUT ${man_out}/../changelog.gz
                   COMMAND ${CMAKE_COMMAND} -E make_directory ${man_out}
                   COMMAND ${CMAKE_COMMAND} -E copy ${pkg}/changelog ${man_out}/../changelog
                   COMMAND ${LOOM_GZIP} -9nf ${man_out}/../changelog
                   DEPENDS ${pkg}/changelog VERBATIM)
add_custom_target(loom_package_docs ALL DEPENDS ${LOOM_MAN_PAGES} ${man_out}/../changelog.gz)
install(FILES ${LOOM_MAN_PAGES} DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT loomctl)

install(FILES ${PROJECT_SOURCE_DIR}/firmware/config/default_loom.toml DESTINATION /etc/loomctl RENAME loom.toml
        COMPONENT loomctl)
install(FILES ${pkg}/loomctl.default DESTINATION /etc/default RENAME loomctl COMPONENT loomctl)
install(FILES ${pkg}/loom-panel.default DESTINATION /etc/default RENAME loom-panel COMPONENT loomctl)
install(FILES ${pkg}/loomctl.service ${pkg}/loom-panel.service DESTINATION /lib/systemd/system COMPONENT loomctl)
file(GLOB LOOM_LCM_FILES ${PROJECT_SOURCE_DIR}/firmware/telemetry/lcmtypes/*.lcm)
install(FILES ${LOOM_LCM_FILES} DESTINATION ${CMAKE_INSTALL_DATADIR}/loomctl/lcmtypes COMPONENT loomctl)
install(FILES ${PROJECT_SOURCE_DIR}/README.md ${pkg}/copyright ${man_out}/../changelog.gz
        DESTINATION ${CMAKE_INSTALL_DATADIR}/doc/loomctl COMPONENT loomctl)

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
set(LOOM_DEB_MAINTAINER "loomctl maintainers <maintainers@users.noreply.h-seed-3434080e.example>"
    CACHE STRING "Maintainer field of the .deb (a real, reachable address)")
set(CPACK_PACKAGE_CONTACT "${LOOM_DEB_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "controller for a mechanised handmade-carpet loom")
set(CPACK_PACKAGE_DESCRIPTION "loomctl drives the shedding, picking, beat-up and carriage
mechanisms of a mechanised handmade-carpet loom over CANopen (SocketCAN),
or a simulated loom, in a fixed-rate real-time loop. The loomctl service
arms the loom and waits for the operator's commands (loomctl ctl, the I/O
node's buttons); telemetry is published over LCM and shown by
loom-monitor, loom-panel (a web page) and loom-spy.")
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${LOOM_DEB_ARCH})
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_STRIP_FILES ON)
# Runtime dependencies by Debian name (tests/board/package_test.sh checks that every library the
# binaries load comes from one of these): the C++ runtime, LCM, toml++, NLopt (loom-dynamics' balancing),
# Google Benchmark (loom-profile's lookup timings), libpng (designs), SQLite (the production record),
# OpenSSL's libcrypto (a job's design hash), cpp-httplib (loom-panel), and adduser for the postinst.
# Names are the same on amd64 and arm64.
set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libc6 (>= 2.36), libstdc++6 (>= 12), libgcc-s1, liblcm1 (>= 1.3.1), libtomlplusplus3 (>= 3.3.0), libnlopt0 (>= 2.7.1), libbenchmark1debian (>= 1.7.1), libpng16-16 (>= 1.6.39), libsqlite3-0 (>= 3.40.1), libssl3 (>= 3.0.0)")
if(TARGET loom-panel)
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS ", libcpp-httplib0.11 (>= 0.11.4)")
endif()
string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS ", adduser")
# loom-spy's Java side (a viewer: boards without a display do without it).
# openssl: the panel's self-signed certificate made at install (postinst; without it, plain HTTP only).
set(CPACK_DEBIAN_PACKAGE_RECOMMENDS "openssl, can-utils, iproute2, default-jre-headless | java11-runtime-headless, liblcm-java, libjchart2d-java")
set(CPACK_DEBIAN_PACKAGE_SUGGESTS "rt-tests, liblcm-bin, xvfb")
foreach(f postinst prerm postrm conffiles)
  configure_file(${pkg}/${f} ${CMAKE_BINARY_DIR}/packaging/${f} COPYONLY)
endforeach()
set(CPACK_DEBIAN_PACKAGE_CONTROL_EXTRA
    "${CMAKE_BINARY_DIR}/packaging/postinst;${CMAKE_BINARY_DIR}/packaging/prerm;${CMAKE_BINARY_DIR}/packaging/postrm;${CMAKE_BINARY_DIR}/packaging/conffiles")
set(CPACK_DEBIAN_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_PACKAGE_DIRECTORY ${CMAKE_BINARY_DIR}/packages)
include(CPack)
