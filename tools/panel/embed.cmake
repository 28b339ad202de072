# Turns the panel's page into a C++ translation unit (`loom::panel::kPanelHtml`), so loom-panel is one
# file with nothing to install beside it.
file(READ ${INPUT} content)
file(WRITE ${OUTPUT} "// Generated from ${INPUT} — do not edit.\nnamespace loom::panel {\nextern const char* const kPanelHtml;\nconst char* const kPanelHtml = R\"LOOMPANEL(${content})LOOMPANEL\";\n}\n")
