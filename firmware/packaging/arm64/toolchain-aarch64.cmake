# Cross-building loomctl for arm64 boards with Debian's cross toolchain (g++-aarch64-linux-gnu) and
# multiarch :arm64 dev packages (tools/deps.sh --arm64). LCM is not multi-arch in Debian (installing
# liblcm-dev:arm64 would remove the host's LCM), so its arm64 pieces come from a sysroot folder of
# extracted .debs: LOOM_ARM64_SYSROOT (default ~/.cache/loomctl/arm64-sysroot). lcm-gen runs on the host.
# Tests run under qemu-user through CMAKE_CROSSCOMPILING_EMULATOR (tools/arm64-run).
set(CMAKE_SYSTEM_NAME Linux)
set(CMAKE_SYSTEM_PROCESSOR aarch64)
set(CMAKE_C_COMPILER aarch64-linux-gnu-gcc)
set(CMAKE_CXX_COMPILER aarch64-linux-gnu-g++)
set(CMAKE_LIBRARY_ARCHITECTURE aarch64-linux-gnu)

if(NOT LOOM_ARM64_SYSROOT)
  if(DEFINED ENV{LOOM_ARM64_SYSROOT})
    set(LOOM_ARM64_SYSROOT $ENV{LOOM_ARM64_SYSROOT})
  else()
    set(LOOM_ARM64_SYSROOT $ENV{HOME}/.cache/loomctl/arm64-sysroot)
  endif()
endif()
set(LOOM_ARM64_SYSROOT ${LOOM_ARM64_SYSROOT} CACHE PATH "extracted arm64 .debs of the non-multiarch dependencies (LCM)")

# The sysroot first (LCM), then the host's multiarch tree (/usr/lib/aarch64-linux-gnu via the library
# architecture), and the cross toolchain's own libc.
set(CMAKE_FIND_ROOT_PATH ${LOOM_ARM64_SYSROOT} / /usr/aarch64-linux-gnu)
set(CMAKE_FIND_ROOT_PATH_MODE_PROGRAM NEVER)   # lcm-gen, ccache: host programs
set(CMAKE_FIND_ROOT_PATH_MODE_LIBRARY ONLY)
set(CMAKE_FIND_ROOT_PATH_MODE_INCLUDE BOTH)
set(CMAKE_FIND_ROOT_PATH_MODE_PACKAGE BOTH)

# liblcm.so needs GLib, which the sysroot also holds: let the linker find it there.
set(_loom_rpl "-Wl,-rpath-link,${LOOM_ARM64_SYSROOT}/usr/lib/aarch64-linux-gnu -Wl,-rpath-link,${LOOM_ARM64_SYSROOT}/lib/aarch64-linux-gnu")
set(CMAKE_EXE_LINKER_FLAGS_INIT "${_loom_rpl}")
set(CMAKE_SHARED_LINKER_FLAGS_INIT "${_loom_rpl}")

get_filename_component(_loom_src ${CMAKE_CURRENT_LIST_DIR}/../../.. ABSOLUTE)
set(CMAKE_CROSSCOMPILING_EMULATOR ${_loom_src}/tools/arm64-run)
