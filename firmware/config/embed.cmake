# Turns a text file into a C++ translation unit defining `const char* const NAME` (build-time embedding
# of the default loom config and scene, so `loomctl` runs with no files at all).
file(READ ${INPUT} content)
file(WRITE ${OUTPUT} "// Generated from ${INPUT} — do not edit.\nnamespace loom::firmware {\nextern const char* const ${NAME};\nconst char* const ${NAME} = R\"LOOMTOML(${content})LOOMTOML\";\n}\n")
