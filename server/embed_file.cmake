# Writes a C++ source that defines `const char NAME[]` holding the text of INPUT, so that a
# page can be edited as HTML and still ship inside the binary.
#   cmake -DINPUT=page.html -DOUTPUT=page.cc -DNAME=kPage -DNAMESPACE=a::b -P embed_file.cmake
file(READ "${INPUT}" content)
string(FIND "${content}" ")hpose_embed\"" clash)
if(NOT clash EQUAL -1)
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )hpose_embed\"")
endif()
file(WRITE "${OUTPUT}.tmp"
  "// Generated from ${INPUT} by embed_file.cmake; edit that file instead.\n"
  "namespace ${NAMESPACE} {\n"
  "extern const char ${NAME}[];\n"
  "const char ${NAME}[] = R\"hpose_embed(${content})hpose_embed\";\n"
  "}  // namespace ${NAMESPACE}\n")
file(RENAME "${OUTPUT}.tmp" "${OUTPUT}")
