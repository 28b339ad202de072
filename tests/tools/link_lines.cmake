# The offline tools' link lines hold no CAN runtime, LCM or simulator: they read a loom file through
# loom::config and nothing that opens a socket or simulates a loom. Reads each executable's link line as
# the build system has it (build.ninja's LINK_LIBRARIES, or a Makefile build's link.txt), not the
# targets' declared dependencies, so a library pulled in transitively is caught too.
#
# cmake -DBUILD_DIR=<build> -DTARGETS="loom-profile;loom-dynamics" [-DEXPECT=forbidden] [-DFORBIDDEN=...]
#       -P link_lines.cmake
#   EXPECT=clean (default): fails naming every target whose link line holds a forbidden library.
#   EXPECT=forbidden: the check's own check — fails unless every target's line holds one (loomctl does).
#   FORBIDDEN: another list of library names for another rule (loom-sim-drive: the simulator and the CAN
#   runtime are its job, the firmware, telemetry and LCM are not).
# A target whose link line cannot be found fails either way, so a renamed target cannot pass unseen.

cmake_minimum_required(VERSION 3.25)

# By library name (lib<name>.a / lib<name>.so* / -l<name>): the SocketCAN CANopen runtime, the simulator,
# the simulated CAN drive, telemetry and LCM, and the firmware that links them all.
set(forbidden loom_drivers loom_sim_hal loom_sim_can_drive loom_telemetry lcm loom_firmware)
set(rule "an offline tool links loom::config, not the runtime")
if(DEFINED FORBIDDEN)
  set(forbidden ${FORBIDDEN})
  list(JOIN forbidden ", " rule)
  set(rule "forbidden here: ${rule}")
endif()

if(NOT DEFINED BUILD_DIR OR NOT DEFINED TARGETS)
  message(FATAL_ERROR
          "usage: cmake -DBUILD_DIR=... -DTARGETS=... [-DEXPECT=forbidden] [-DFORBIDDEN=...] -P link_lines.cmake")
endif()
if(NOT DEFINED EXPECT)
  set(EXPECT clean)
endif()

# The link line of `target`: build.ninja names its link rule CXX_EXECUTABLE_LINKER__<target>_<config>
# and gives the libraries on the LINK_LIBRARIES line that follows; a Makefile build writes link.txt.
function(link_line target out)
  set(ninja ${BUILD_DIR}/build.ninja)
  if(EXISTS ${ninja})
    file(STRINGS ${ninja} lines REGEX "^build .*: CXX_EXECUTABLE_LINKER__${target}_|^  LINK_LIBRARIES = ")
    set(in_target FALSE)
    foreach(line IN LISTS lines)
      if(line MATCHES "^build ")
        string(FIND "${line}" "CXX_EXECUTABLE_LINKER__${target}_" at)
        if(at GREATER -1)
          set(in_target TRUE)
        endif()
      elseif(in_target)
        string(REGEX REPLACE "^  LINK_LIBRARIES = " "" libs "${line}")
        set(${out} "${libs}" PARENT_SCOPE)
        return()
      endif()
    endforeach()
  endif()
  file(GLOB_RECURSE txt ${BUILD_DIR}/*/CMakeFiles/${target}.dir/link.txt)
  if(txt)
    list(GET txt 0 first)
    file(READ ${first} libs)
    set(${out} "${libs}" PARENT_SCOPE)
    return()
  endif()
  set(${out} "" PARENT_SCOPE)
endfunction()

set(failures "")
foreach(target IN LISTS TARGETS)
  link_line(${target} libs)
  if(libs STREQUAL "")
    string(APPEND failures "  ${target}: no link line found under ${BUILD_DIR}\n")
    continue()
  endif()
  separate_arguments(tokens UNIX_COMMAND "${libs}")
  set(found "")
  foreach(token IN LISTS tokens)
    get_filename_component(name "${token}" NAME)
    string(REGEX REPLACE "^-l" "lib" name "${name}")
    if(NOT name MATCHES "^lib")
      continue()
    endif()
    string(REGEX REPLACE "^lib([^.]+)\\..*$" "\\1" name "${name}")  # libfoo.so.1.2 -> foo
    string(REGEX REPLACE "^lib" "" name "${name}")                  # -lfoo -> foo
    if(name IN_LIST forbidden AND NOT name IN_LIST found)
      list(APPEND found ${name})
    endif()
  endforeach()
  if(EXPECT STREQUAL "clean" AND found)
    list(JOIN found ", " names)
    string(APPEND failures "  ${target} links ${names} (${rule})\n")
  elseif(EXPECT STREQUAL "forbidden" AND NOT found)
    string(APPEND failures "  ${target}: no forbidden library found, yet it links the runtime: the check is blind\n")
  else()
    message(STATUS "${target}: ok (${EXPECT})")
  endif()
endforeach()

if(failures)
  message(FATAL_ERROR "link lines:\n${failures}")
endif()
