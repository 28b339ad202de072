# Debian's hardening flags for what ships in the .deb (lintian: hardening-no-bindnow,
# hardening-no-fortify-functions): _FORTIFY_SOURCE=2 (checked libc calls where sizes are known; needs
# optimisation, so not in Debug), the strong stack protector, and full RELRO with immediate binding
# (-z relro -z now). Executables are PIE already (GCC's default on Debian). Not in the sanitizer and
# fuzz builds, which have their own instrumentation and ship nothing.
if(NOT LOOM_SANITIZE AND NOT LOOM_FUZZ AND NOT LOOM_TSAN)
  add_compile_options(-fstack-protector-strong $<$<NOT:$<CONFIG:Debug>>:-D_FORTIFY_SOURCE=2>)
  add_link_options(-Wl,-z,relro -Wl,-z,now)
endif()
