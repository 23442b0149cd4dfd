#!/usr/bin/env python3
"""Generates the project's protocol headers from idl/crane_msgs.idl (build time, never committed).

The IDL is the one place where a message's fields and the protocol's codes are written; this
writes what repeats them:

  gen_protocol.py IDL --messages OUT.hpp   crane::protocol: a plain struct per message (no DDS),
                                           its codes (the IDL's <Name>_Constants) as static
                                           constexpr members and a name table, all_finite() and
                                           visit_fields() (names and values, for echo and records)
  gen_protocol.py IDL --dds OUT.hpp        to_dds() / from_dds() between those structs and the
                                           fastddsgen classes (the DDS transport's types)
  gen_protocol.py IDL --schema OUT.hpp     crane::protocol::kIdlSchema: the IDL's text as a string
                                           constant (a Foxglove channel's omgidl schema), its hex
                                           literals written in decimal (Foxglove's omgidl parser
                                           reads no hex); the text is otherwise unchanged
  gen_protocol.py IDL --ros2-schemas OUT.hpp   crane::protocol::kRos2Schemas: each message's ROS 2 type
                                           name and its .msg with its dependencies (MCAP's ros2msg
                                           schema encoding, for crane_topic record --mcap)
  gen_protocol.py IDL --msg-dir DIR        the ROS 2 interface files DIR/<Name>.msg (rosidl's .msg
                                           syntax, constants and the IDL's comments included)
  gen_protocol.py IDL --ros2-package DIR --package-files SRC
                                           the complete ROS 2 interface package in DIR: package.xml,
                                           CMakeLists.txt and README.md copied from SRC
                                           (deploy/ros2/crane_msgs), msg/<Name>.msg (.msg files of
                                           messages no longer in the IDL are removed) and
                                           msg_files.cmake, the list of them for CMakeLists.txt

Exit 1 with a message on an IDL construct the parser (idl_structs.py) does not know.
"""
import argparse
import pathlib
import re
import sys

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
import idl_structs  # noqa: E402

HEADER = "// Generated from {idl} by idl/tools/gen_protocol.py at build time. Do not edit.\n"

CPP_TYPES = {"double": "double", "float": "float", "boolean": "bool", "octet": "std::uint8_t", "char": "char",
             "int8": "std::int8_t", "uint8": "std::uint8_t", "int16": "std::int16_t", "uint16": "std::uint16_t",
             "int32": "std::int32_t", "uint32": "std::uint32_t", "int64": "std::int64_t", "uint64": "std::uint64_t"}
ROS_TYPES = {"double": "float64", "float": "float32", "boolean": "bool", "octet": "byte", "char": "char",
             "int8": "int8", "uint8": "uint8", "int16": "int16", "uint16": "uint16", "int32": "int32",
             "uint32": "uint32", "int64": "int64", "uint64": "uint64"}


def plain(name):
    """C++ name of a message's plain struct: the IDL name without its trailing underscore."""
    return name[:-1] if name.endswith("_") else name


def field_type(f):
    base = CPP_TYPES[f.idl_type] if f.primitive else plain(f.idl_type)
    return f"std::array<{base}, {f.size}>" if f.size else base


def messages(structs, constants, idl_name):
    out = [HEADER.format(idl=idl_name)]
    out.append('''#pragma once
// The crane protocol without DDS: one plain struct per message of idl/crane_msgs.idl (same names
// without the trailing underscore, same fields, SI units as commented there), the protocol's codes
// and bit masks (the IDL's <Name>_Constants modules) as static constexpr members of their message,
// and the per-message code that would otherwise repeat each field list:
//   all_finite(m)          every floating-point field (arrays included) is finite: the NaN gate
//   visit_fields(m, v)     v(name, value) for every field in IDL order, nested structs as such
//   code_name(...)         the name of a code ("stage_silent" for FAULT_STAGE_SILENT)
// Stage objects (the cores of the processes) read and write these structs; the DDS translation is
// crane/protocol/dds.hpp, the ROS 2 .msg files are generated from the same IDL.
#include <array>
#include <cmath>
#include <cstdint>
#include <span>
#include <string_view>

namespace crane::protocol {

/// One named code of the IDL: `group` is the constant's first word (FAULT), `name` the rest in
/// lower case (stage_silent).
struct NamedCode {
  std::string_view group;
  std::string_view name;
  std::uint64_t value;
};

/// The name of `value` within `group` of `codes` (a message's kCodes), or "unknown".
[[nodiscard]] constexpr std::string_view code_name(std::span<const NamedCode> codes, std::string_view group,
                                                   std::uint64_t value) noexcept {
  for (const auto& c : codes) {
    if (c.group == group && c.value == value) return c.name;
  }
  return "unknown";
}

namespace detail {
[[nodiscard]] inline bool finite(double v) noexcept { return std::isfinite(v); }
[[nodiscard]] inline bool finite(float v) noexcept { return std::isfinite(v); }
template <class T, std::size_t N>
[[nodiscard]] bool finite(const std::array<T, N>& values) noexcept {
  for (const auto& v : values) {
    if (!finite(v)) return false;
  }
  return true;
}
}  // namespace detail

''')
    by_owner = {}
    for c in constants:
        by_owner.setdefault(c.owner, []).append(c)
    for s in structs:
        name = plain(s.name)
        out.append(f"/// {s.scoped_name} (DDS type name).\n")
        out.append(f"struct {name} {{\n")
        out.append(f'  static constexpr std::string_view kTypeName = "{s.scoped_name}";\n')
        codes = by_owner.get(name, [])
        for c in codes:
            comment = f"  // {c.comment}" if c.comment else ""
            out.append(f"  static constexpr {CPP_TYPES[c.idl_type]} {c.name} = {c.value};{comment}\n")
        if codes:
            out.append(f"  static constexpr std::array<NamedCode, {len(codes)}> kCodes{{{{\n")
            for c in codes:
                out.append(f'      {{"{c.group}", "{c.member}", {c.value}U}},\n')
            out.append("  }};\n")
        for f in s.fields:
            comment = f"  // {f.comment}" if f.comment else ""
            out.append(f"  {field_type(f)} {f.name}{{}};{comment}\n")
        out.append("};\n\n")
    # all_finite: declarations first (nested structs check through each other).
    for s in structs:
        out.append(f"[[nodiscard]] inline bool all_finite(const {plain(s.name)}& m) noexcept;\n")
    out.append("\n")
    for s in structs:
        terms = []
        for f in s.fields:
            if f.primitive and f.idl_type in ("double", "float"):
                terms.append(f"detail::finite(m.{f.name})")
            elif not f.primitive:
                if f.size:
                    terms.append(f"std::all_of(m.{f.name}.begin(), m.{f.name}.end(), "
                                 f"[](const auto& e) {{ return all_finite(e); }})")
                else:
                    terms.append(f"all_finite(m.{f.name})")
        body = " &&\n         ".join(terms) if terms else "true"
        unused = "" if terms else "  (void)m;\n"
        out.append(f"inline bool all_finite(const {plain(s.name)}& m) noexcept {{\n{unused}  return {body};\n}}\n")
    out.append("\n")
    for const in ("const ", ""):
        for s in structs:
            out.append(f"template <class Visitor>\nvoid visit_fields({const}{plain(s.name)}& m, Visitor&& visit) {{\n")
            for f in s.fields:
                out.append(f'  visit("{f.name}", m.{f.name});\n')
            out.append("}\n")
    out.append("\n}  // namespace crane::protocol\n")
    text = "".join(out)
    if "std::all_of" in text:
        text = text.replace("#include <array>\n", "#include <algorithm>\n#include <array>\n", 1)
    return text


def dds(structs, idl_name):
    out = [HEADER.format(idl=idl_name)]
    out.append('''#pragma once
// Translation between the plain protocol structs (crane/protocol/messages.hpp) and the classes
// fastddsgen generates for the DDS transport, field for field: the only place the two meet.
#include <algorithm>

#include "crane/protocol/messages.hpp"
#include "crane_msgs.h"

namespace crane::protocol {

''')
    for s in structs:
        out.append(f"inline void to_dds(const {plain(s.name)}& in, {s.scoped_name}& out);\n")
        out.append(f"inline void from_dds(const {s.scoped_name}& in, {plain(s.name)}& out);\n")
    out.append("\n")
    for s in structs:
        to = [f"inline void to_dds(const {plain(s.name)}& in, {s.scoped_name}& out) {{"]
        fr = [f"inline void from_dds(const {s.scoped_name}& in, {plain(s.name)}& out) {{"]
        for f in s.fields:
            n = f.name
            if f.primitive and not f.size:
                to.append(f"  out.{n}(in.{n});")
                fr.append(f"  out.{n} = in.{n}();")
            elif f.primitive:
                to.append(f"  std::copy(in.{n}.begin(), in.{n}.end(), out.{n}().begin());")
                fr.append(f"  std::copy(in.{n}().begin(), in.{n}().end(), out.{n}.begin());")
            elif not f.size:
                to.append(f"  to_dds(in.{n}, out.{n}());")
                fr.append(f"  from_dds(in.{n}(), out.{n});")
            else:
                to.append(f"  for (std::size_t i = 0; i < {f.size}; ++i) to_dds(in.{n}[i], out.{n}()[i]);")
                fr.append(f"  for (std::size_t i = 0; i < {f.size}; ++i) from_dds(in.{n}()[i], out.{n}[i]);")
        out.append("\n".join(to) + "\n}\n")
        out.append("\n".join(fr) + "\n}\n")
    out.append("\n/// The plain struct of a fastddsgen class, and back.\n"
               "template <class Dds>\nstruct PlainOf;\n")
    for s in structs:
        out.append(f"template <>\nstruct PlainOf<{s.scoped_name}> {{\n  using type = {plain(s.name)};\n}};\n")
    out.append("\n}  // namespace crane::protocol\n")
    return "".join(out)


def msg_comment(text):
    """A comment for a .msg file: rosidl reads everything after the first # as the comment."""
    return f"# {text}" if text else "#"


def msg_text(s, structs, constants, idl_name):
    """The ROS 2 .msg text of struct `s` (rosidl's .msg syntax, rosidl_adapter.parser): the leading
    # lines are the message's comment, a constant is `TYPE NAME=VALUE`, a field `TYPE name` or
    `TYPE[N] name`, a type of another package `pkg/Type`; a trailing `# ...` and whole-line comments
    right above belong to the element below."""
    modules_of = {x.name: x.modules for x in structs}
    name = plain(s.name)
    lines = [msg_comment(line) for line in s.leading]
    lines += [f"# Generated from {idl_name} ({s.scoped_name}) by idl/tools/gen_protocol.py. Do not edit.", ""]
    codes = [c for c in constants if c.owner == name]
    for c in codes:
        lines += [msg_comment(line) for line in c.leading]
        comment = f"  # {c.comment}" if c.comment else ""
        lines.append(f"{ROS_TYPES[c.idl_type]} {c.name}={c.value}{comment}")
    if codes:
        lines.append("")
    for f in s.fields:
        if f.primitive:
            ros = ROS_TYPES[f.idl_type]
        elif modules_of[f.idl_type][0] != "crane_msgs":
            ros = f"{modules_of[f.idl_type][0]}/{plain(f.idl_type)}"  # builtin_interfaces/Time
        else:
            ros = plain(f.idl_type)
        lines += [msg_comment(line) for line in f.leading]
        comment = f"  # {f.comment}" if f.comment else ""
        lines.append(f"{ros}{f'[{f.size}]' if f.size else ''} {f.name}{comment}")
    return "\n".join(lines) + "\n"


def msg_files(structs, constants, idl_name):
    """{file name: text} of the ROS 2 .msg files of module crane_msgs::msg::dds_."""
    return {f"{plain(s.name)}.msg": msg_text(s, structs, constants, idl_name)
            for s in structs if s.modules == ["crane_msgs", "msg", "dds_"]}


def ros2_type_name(s):
    """crane_msgs::msg::dds_::SensorSample_ -> crane_msgs/msg/SensorSample (ROS 2's resource name)."""
    return f"{s.modules[0]}/msg/{plain(s.name)}"


def ros2_schemas(structs, constants, idl_name):
    """crane::protocol::kRos2Schemas: per message of crane_msgs::msg::dds_, its ROS 2 type name and
    its schema as MCAP's ros2msg encoding writes it (registry.md, "ros2msg"): the message's .msg
    text, then each type it uses (depth first, each once) after a line of 80 '=' and a line
    'MSG: <package>/msg/<Type>'."""
    by_name = {x.name: x for x in structs}
    entries = []
    for s in structs:
        if s.modules != ["crane_msgs", "msg", "dds_"]:
            continue
        order = []

        def visit(t):
            for f in t.fields:
                if not f.primitive and f.idl_type not in order:
                    order.append(f.idl_type)
                    visit(by_name[f.idl_type])

        visit(s)
        text = msg_text(s, structs, constants, idl_name)
        for dep in order:
            text += "=" * 80 + f"\nMSG: {ros2_type_name(by_name[dep])}\n" + msg_text(by_name[dep], structs, constants, idl_name)
        if ")crane_msg\"" in text:
            raise SystemExit(f"{idl_name}: contains the raw-string delimiter )crane_msg\"")
        entries.append(f'    {{"{s.scoped_name}", "{ros2_type_name(s)}", R"crane_msg({text})crane_msg"}}')
    return (HEADER.format(idl=idl_name) + "#pragma once\n#include <array>\n#include <string_view>\n\n"
            "namespace crane::protocol {\n\n"
            "/// A message's ROS 2 interface: its resource name and its schema in MCAP's ros2msg encoding.\n"
            "struct Ros2Schema {\n"
            "  std::string_view dds_type_name;   // crane_msgs::msg::dds_::SensorSample_\n"
            "  std::string_view ros2_type_name;  // crane_msgs/msg/SensorSample\n"
            "  std::string_view msg_definition;  // the .msg, then its dependencies, delimited\n"
            "};\n\n"
            f"inline constexpr std::array<Ros2Schema, {len(entries)}> kRos2Schemas{{{{\n" + ",\n".join(entries) + "}};\n\n"
            "/// The schema of DDS type `dds_type_name`, or nullptr when the IDL has no such message.\n"
            "[[nodiscard]] constexpr const Ros2Schema* ros2_schema(std::string_view dds_type_name) noexcept {\n"
            "  for (const auto& s : kRos2Schemas) {\n"
            "    if (s.dds_type_name == dds_type_name) return &s;\n"
            "  }\n"
            "  return nullptr;\n"
            "}\n\n"
            "}  // namespace crane::protocol\n")


def ros2_package(structs, constants, idl_name, out_dir, package_files):
    """Writes the ROS 2 package into out_dir (see the module's docstring)."""
    out_dir = pathlib.Path(out_dir)
    for name in ("package.xml", "CMakeLists.txt", "README.md"):
        write_if_changed(out_dir / name, (pathlib.Path(package_files) / name).read_text())
    files = msg_files(structs, constants, idl_name)
    for name, text in files.items():
        write_if_changed(out_dir / "msg" / name, text)
    for stale in (out_dir / "msg").glob("*.msg"):
        if stale.name not in files:
            stale.unlink()
    listing = "".join(f'  "msg/{name}"\n' for name in files)
    write_if_changed(out_dir / "msg_files.cmake",
                     f"# Generated from {idl_name} by idl/tools/gen_protocol.py. Do not edit.\n"
                     f"# The interface files of this package, one per struct of crane_msgs::msg::dds_.\n"
                     f"set(CRANE_MSG_FILES\n{listing})\n")


def schema(idl_text, idl_name):
    """The IDL as a C++ string constant, for channels whose schema encoding is omgidl."""
    text = re.sub(r"\b0[xX]([0-9a-fA-F]+)\b", lambda m: str(int(m.group(1), 16)), idl_text)
    delimiter = "crane_idl"
    if ")" + delimiter + '"' in text:
        raise SystemExit(f"{idl_name}: contains the raw-string delimiter ){delimiter}\"")
    return (HEADER.format(idl=idl_name) + "#pragma once\n#include <string_view>\n\nnamespace crane::protocol {\n\n"
            f"/// {idl_name}, every message type of the bus in OMG IDL (schema encoding \"omgidl\"), hex\n"
            "/// literals in decimal. Root type names are the DDS type names (crane_msgs::msg::dds_::<Name>_).\n"
            f'inline constexpr std::string_view kIdlSchema = R"{delimiter}({text}){delimiter}";\n\n'
            "}  // namespace crane::protocol\n")


def write_if_changed(target, text):
    target = pathlib.Path(target)
    if not target.exists() or target.read_text() != text:  # unchanged output: no rebuild
        target.parent.mkdir(parents=True, exist_ok=True)
        target.write_text(text)


def main():
    parser = argparse.ArgumentParser(description="Generates the protocol's code from the IDL.")
    parser.add_argument("idl", type=pathlib.Path)
    what = parser.add_mutually_exclusive_group(required=True)
    what.add_argument("--messages", metavar="OUT.hpp")
    what.add_argument("--dds", metavar="OUT.hpp")
    what.add_argument("--schema", metavar="OUT.hpp")
    what.add_argument("--ros2-schemas", metavar="OUT.hpp")
    what.add_argument("--msg-dir", metavar="DIR")
    what.add_argument("--ros2-package", metavar="DIR")
    parser.add_argument("--package-files", metavar="SRC", help="with --ros2-package: package.xml, "
                        "CMakeLists.txt and README.md are copied from SRC")
    args = parser.parse_args()
    if args.ros2_package and not args.package_files:
        parser.error("--ros2-package needs --package-files")
    idl = args.idl
    structs, constants = idl_structs.parse_all(idl.read_text())
    if args.messages:
        write_if_changed(args.messages, messages(structs, constants, idl.name))
    elif args.dds:
        write_if_changed(args.dds, dds(structs, idl.name))
    elif args.ros2_schemas:
        write_if_changed(args.ros2_schemas, ros2_schemas(structs, constants, idl.name))
    elif args.schema:
        write_if_changed(args.schema, schema(idl.read_text(), idl.name))
    elif args.msg_dir:
        for name, text in msg_files(structs, constants, idl.name).items():
            write_if_changed(pathlib.Path(args.msg_dir) / name, text)
    else:
        ros2_package(structs, constants, idl.name, args.ros2_package, args.package_files)
    return 0


if __name__ == "__main__":
    sys.exit(main())
