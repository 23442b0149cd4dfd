#!/usr/bin/env python3
"""Checks deploy/ros2/crane_msgs/msg/*.msg against idl/crane_msgs.idl field by field.

Every struct Name_ of module crane_msgs::msg::dds_ must have a Name.msg with the same fields, in
the same order, with the ROS 2 type that rosidl maps to the IDL type (so a ROS 2 node built from
the package reads and writes our topics); no .msg may exist without its struct. Exit code 0 when
they agree, 1 with one line per difference otherwise.
Usage: check_msgs.py IDL_FILE MSG_DIR
       check_msgs.py IDL_FILE --fields-header deploy/launcher/src/topic_fields.hpp
(the second form checks crane_topic's JSON field tables against the IDL the same way)
"""
import pathlib
import re
import sys

PRIMITIVES = {"double": "float64", "float": "float32", "boolean": "bool", "octet": "byte", "char": "char",
              "int8": "int8", "uint8": "uint8", "int16": "int16", "uint16": "uint16", "int32": "int32",
              "uint32": "uint32", "int64": "int64", "uint64": "uint64"}


def idl_structs(text):
    """{name: [(ros_type, field)]} for the structs of crane_msgs::msg::dds_."""
    text = re.sub(r"//[^\n]*", "", text)
    module = text[text.index("module crane_msgs"):]
    structs = {}
    for match in re.finditer(r"struct\s+(\w+)_\s*\{(.*?)\};", module, re.S):
        fields = []
        for decl in match.group(2).split(";"):
            decl = decl.strip()
            if not decl:
                continue
            m = re.fullmatch(r"([\w:]+)\s+(\w+)(\[(\d+)\])?", decl)
            if not m:
                raise SystemExit(f"unparsed IDL declaration in {match.group(1)}_: {decl!r}")
            idl_type, name, _, size = m.groups()
            if idl_type in PRIMITIVES:
                ros = PRIMITIVES[idl_type]
            elif idl_type == "builtin_interfaces::msg::dds_::Time_":
                ros = "builtin_interfaces/Time"
            elif re.fullmatch(r"\w+_", idl_type):
                ros = idl_type[:-1]
            else:
                raise SystemExit(f"unmapped IDL type {idl_type} in {match.group(1)}_")
            fields.append((ros + (f"[{size}]" if size else ""), name))
        structs[match.group(1)] = fields
    return structs


def msg_fields(path):
    fields = []
    for line in path.read_text().splitlines():
        line = line.split("#", 1)[0].strip()
        if line:
            ros_type, name = line.split()[:2]
            fields.append((ros_type, name))
    return fields


def check_fields_header(structs, header):
    text = header.read_text()
    problems = []
    for name, fields in structs.items():
        if name == "CycleHeader":
            continue
        m = re.search(r"inline json to_json\(const msgs::%s_& m\) \{(.*?)\n\}" % name, text, re.S)
        if not m:
            problems.append(f"{header.name}: no to_json for {name}_")
            continue
        got = re.findall(r'j\["(\w+)"\]', m.group(1))
        want = [f for _, f in fields]
        if got != want:
            problems.append(f"{header.name} {name}_: IDL fields {want}, table {got}")
    for p in problems:
        print(p)
    print(f"{len(structs) - 1} field tables checked, {len(problems)} differences")
    return 1 if problems else 0


def main():
    idl = pathlib.Path(sys.argv[1])
    structs = idl_structs(idl.read_text())
    if sys.argv[2] == "--fields-header":
        return check_fields_header(structs, pathlib.Path(sys.argv[3]))
    msg_dir = pathlib.Path(sys.argv[2])
    problems = []
    for name, fields in structs.items():
        path = msg_dir / f"{name}.msg"
        if not path.exists():
            problems.append(f"{path}: missing (IDL struct {name}_)")
            continue
        got = msg_fields(path)
        for i in range(max(len(fields), len(got))):
            want = fields[i] if i < len(fields) else None
            have = got[i] if i < len(got) else None
            if want != have:
                problems.append(f"{path.name} field {i + 1}: IDL says {want}, .msg says {have}")
    for path in sorted(msg_dir.glob("*.msg")):
        if path.stem not in structs:
            problems.append(f"{path}: no IDL struct {path.stem}_")
    for p in problems:
        print(p)
    print(f"{len(structs)} message types, {sum(len(f) for f in structs.values())} fields checked, "
          f"{len(problems)} differences")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
