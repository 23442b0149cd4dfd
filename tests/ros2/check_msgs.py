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

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "idl" / "tools"))
import idl_structs  # noqa: E402  (the one IDL parser of the project)

ROS_TYPES = {"double": "float64", "float": "float32", "boolean": "bool", "octet": "byte", "char": "char",
             "int8": "int8", "uint8": "uint8", "int16": "int16", "uint16": "uint16", "int32": "int32",
             "uint32": "uint32", "int64": "int64", "uint64": "uint64"}


def idl_structs_of(text):
    """{name: [(ros_type, field)]} for the structs of crane_msgs::msg::dds_ (name without the _)."""
    structs = {}
    for s in idl_structs.parse(text):
        if s.modules != ["crane_msgs", "msg", "dds_"]:
            continue
        fields = []
        for f in s.fields:
            if f.primitive:
                ros = ROS_TYPES[f.idl_type]
            elif f.idl_type == "Time_":
                ros = "builtin_interfaces/Time"
            else:
                ros = f.idl_type[:-1]
            fields.append((ros + (f"[{f.size}]" if f.size else ""), f.name))
        structs[s.name[:-1]] = fields
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
    structs = idl_structs_of(idl.read_text())
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
