#!/usr/bin/env python3
"""Generates the Cyclone DDS type support of the transport from idl/crane_msgs.idl (build time).

The canonical in-process message is the C++ class that fastddsgen generates; Cyclone DDS works on
the C struct that idlc generates from the same IDL. This writes, for every struct of the IDL, the
two field-by-field conversions and a table entry that the Cyclone adapter looks up by DDS type
name (idl/transport/src/cyclone_type_support.hpp):

  gen_cyclone_support.py IDL --support OUT.cpp   conversions + find_cyclone_type_support()
  gen_cyclone_support.py IDL --random OUT.hpp    fill_random(message, rng) for every type (tests)

Exit 1 with a message on an IDL construct the parser does not know.
"""
import pathlib
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import idl_structs  # noqa: E402

HEADER = "// Generated from {idl} by idl/tools/gen_cyclone_support.py at build time. Do not edit.\n"


def cpp_class(structs_by_name, name):
    return structs_by_name[name].scoped_name


def support(structs, idl_name):
    by_name = {s.name: s for s in structs}
    out = [HEADER.format(idl=idl_name)]
    out.append('#include <algorithm>\n#include <cstring>\n#include <iterator>\n#include <string_view>\n\n'
               '#include "crane_msgs.h"            // fastddsgen: the C++ classes\n'
               '#include "cyclone/crane_msgs.h"    // idlc: the C structs\n'
               '#include "cyclone_type_support.hpp"\n\n'
               'namespace crane::transport::detail {\nnamespace {\n\n')
    for s in structs:  # declarations first: nested structs convert through each other
        out.append(f"void to_c(const {s.scoped_name}& in, {s.c_name}& out);\n")
        out.append(f"void from_c(const {s.c_name}& in, {s.scoped_name}& out);\n")
    out.append("\n")
    for s in structs:
        to = [f"void to_c(const {s.scoped_name}& in, {s.c_name}& out) {{"]
        fr = [f"void from_c(const {s.c_name}& in, {s.scoped_name}& out) {{"]
        for f in s.fields:
            n = f.name
            if f.size is None:
                if f.primitive:
                    to.append(f"  out.{n} = in.{n}();")
                    fr.append(f"  out.{n}() = in.{n};")
                else:
                    to.append(f"  to_c(in.{n}(), out.{n});")
                    fr.append(f"  from_c(in.{n}, out.{n}());")
            else:
                if f.primitive:
                    to.append(f"  std::copy(in.{n}().begin(), in.{n}().end(), std::begin(out.{n}));")
                    fr.append(f"  std::copy(std::begin(in.{n}), std::end(in.{n}), out.{n}().begin());")
                else:
                    to.append(f"  for (std::size_t i = 0; i < {f.size}; ++i) to_c(in.{n}()[i], out.{n}[i]);")
                    fr.append(f"  for (std::size_t i = 0; i < {f.size}; ++i) from_c(in.{n}[i], out.{n}()[i]);")
        out.append("\n".join(to) + "\n}\n")
        out.append("\n".join(fr) + "\n}\n\n")
    out.append("template <class Message, class C>\nconstexpr CycloneTypeSupport entry(const char* name, "
               "const dds_topic_descriptor_t* descriptor) {\n"
               "  return CycloneTypeSupport{name, descriptor, sizeof(C),\n"
               "      [](const void* m, void* c) { to_c(*static_cast<const Message*>(m), *static_cast<C*>(c)); },\n"
               "      [](const void* c, void* m) { from_c(*static_cast<const C*>(c), *static_cast<Message*>(m)); }};\n"
               "}\n\n")
    out.append("const CycloneTypeSupport kTable[] = {\n")
    for s in structs:
        out.append(f'    entry<{s.scoped_name}, {s.c_name}>("{s.scoped_name}", &{s.c_name}_desc),\n')
    out.append("};\n\n}  // namespace\n\n")
    out.append("const CycloneTypeSupport* find_cyclone_type_support(std::string_view type_name) noexcept {\n"
               "  for (const auto& e : kTable) {\n"
               "    if (type_name == e.type_name) return &e;\n"
               "  }\n  return nullptr;\n}\n\n"
               "std::size_t cyclone_type_count() noexcept { return std::size(kTable); }\n\n"
               "}  // namespace crane::transport::detail\n")
    return "".join(out)


def random_filler(structs, idl_name):
    out = [HEADER.format(idl=idl_name)]
    out.append("#pragma once\n// fill_random(message, rng): every field of every message type drawn at random "
               "(seeded by the caller),\n// for tests that compare messages field by field after a trip through "
               "DDS.\n#include <cstdint>\n#include <limits>\n#include <random>\n\n#include \"crane_msgs.h\"\n\n"
               "namespace crane::transport::testing {\n\n"
               "template <class T, class Rng>\nT random_value(Rng& rng) {\n"
               "  if constexpr (std::is_same_v<T, bool>) {\n    return std::bernoulli_distribution(0.5)(rng);\n"
               "  } else if constexpr (std::is_floating_point_v<T>) {\n"
               "    return std::uniform_real_distribution<T>(T(-1e3), T(1e3))(rng);\n"
               "  } else {\n    using Wide = std::conditional_t<std::is_signed_v<T>, std::int64_t, std::uint64_t>;\n"
               "    return static_cast<T>(std::uniform_int_distribution<Wide>(std::numeric_limits<T>::min(),"
               " std::numeric_limits<T>::max())(rng));\n  }\n}\n\n")
    for s in structs:
        out.append(f"template <class Rng>\nvoid fill_random({s.scoped_name}& m, Rng& rng);\n")
    for s in structs:
        lines = [f"template <class Rng>\nvoid fill_random({s.scoped_name}& m, Rng& rng) {{"]
        for f in s.fields:
            n = f.name
            if f.size is None:
                if f.primitive:
                    lines.append(f"  m.{n}() = random_value<std::decay_t<decltype(m.{n}())>>(rng);")
                else:
                    lines.append(f"  fill_random(m.{n}(), rng);")
            else:
                if f.primitive:
                    lines.append(f"  for (auto& v : m.{n}()) v = random_value<std::decay_t<decltype(v)>>(rng);")
                else:
                    lines.append(f"  for (auto& v : m.{n}()) fill_random(v, rng);")
        out.append("\n".join(lines) + "\n}\n\n")
    out.append("}  // namespace crane::transport::testing\n")
    return "".join(out)


def main():
    if len(sys.argv) != 4 or sys.argv[2] not in ("--support", "--random"):
        raise SystemExit("usage: gen_cyclone_support.py IDL --support OUT.cpp | --random OUT.hpp")
    idl = pathlib.Path(sys.argv[1])
    structs = idl_structs.parse(idl.read_text())
    text = support(structs, idl.name) if sys.argv[2] == "--support" else random_filler(structs, idl.name)
    target = pathlib.Path(sys.argv[3])
    if not target.exists() or target.read_text() != text:  # unchanged output: no rebuild
        target.write_text(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
