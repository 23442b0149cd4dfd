#!/usr/bin/python3
"""Checks the generated ROS 2 package (build/ros2/crane_msgs) with rosidl's own parsers.

What `rosidl_generate_interfaces` does on a ROS 2 machine, up to the code generators: every
msg/<Name>.msg is read by rosidl_adapter's .msg parser (its field types must be known: this
package's messages or builtin_interfaces/Time), converted to a .idl by rosidl_adapter's template,
and that .idl parsed by rosidl_parser. Any error fails the check, naming the file. The parsed
result must then equal the IDL as the project's one parser reads it (idl/tools/idl_structs.py): one
message per struct of crane_msgs::msg::dds_, the same fields in the same order with the types
rosidl maps them to, the same constants (type, name, value). The package must also be complete:
package.xml names crane_msgs, CMakeLists.txt and README.md are there, msg_files.cmake lists
exactly the .msg files. Last, two mutations of a copy (a field removed, a constant changed) must
be caught, so the comparison is known to fail when it should.

Usage: check_msg_package.py IDL_FILE PACKAGE_DIR. Exit code 0 when all holds, 1 with one line per
problem otherwise. Needs Debian's python3-rosidl and python3-empy (deploy/crane installs them).
"""
import pathlib
import re
import shutil
import sys
import tempfile
import xml.etree.ElementTree as ElementTree

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "idl" / "tools"))
import idl_structs  # noqa: E402  (the one IDL parser of the project)

try:
    from rosidl_adapter import parser as msg_parser  # noqa: E402
    from rosidl_adapter.msg import convert_msg_to_idl  # noqa: E402
    from rosidl_parser import definition  # noqa: E402
    from rosidl_parser.parser import parse_idl_file  # noqa: E402
except ImportError as error:
    raise SystemExit(f"rosidl is missing ({error}): install Debian's python3-rosidl and python3-empy "
                     "(deploy/crane build does)")

PACKAGE = "crane_msgs"


def expected_messages(structs, constants):
    """{Name: (fields [(type, name)], constants [(type, NAME, value)])} from the IDL, in the
    spelling of rosidl_parser (the module path without dds_, no trailing underscore)."""
    modules_of = {s.name: s.modules for s in structs}
    messages = {}
    for s in structs:
        if s.modules != [PACKAGE, "msg", "dds_"]:
            continue
        fields = []
        for f in s.fields:
            if f.primitive:
                base = f.idl_type
            else:
                base = "::".join([m for m in modules_of[f.idl_type] if m != "dds_"] + [f.idl_type[:-1]])
            fields.append((f"{base}[{f.size}]" if f.size else base, f.name))
        codes = [(c.idl_type, c.name, c.value) for c in constants if c.owner == s.name[:-1]]
        messages[s.name[:-1]] = (fields, codes)
    return messages


def type_name(t):
    if isinstance(t, definition.Array):
        return f"{type_name(t.value_type)}[{t.size}]"
    if isinstance(t, definition.NamespacedType):
        return "::".join(list(t.namespaces) + [t.name])
    if isinstance(t, definition.BasicType):
        return t.typename
    return f"<{type(t).__name__}: not a fixed-size type>"


def parse_with_rosidl(package_dir, problems):
    """{Name: (fields, constants)} as rosidl reads the package's msg/*.msg."""
    msg_files = sorted((package_dir / "msg").glob("*.msg"))
    known = {msg_parser.BaseType(f"{PACKAGE}/{f.stem}") for f in msg_files}
    known.add(msg_parser.BaseType("builtin_interfaces/Time"))  # the package's <depend>
    parsed = {}
    with tempfile.TemporaryDirectory() as tmp:
        idl_root = pathlib.Path(tmp)
        for f in msg_files:
            try:
                spec = msg_parser.parse_message_file(PACKAGE, str(f))
                msg_parser.validate_field_types(spec, known)
                # (prints the files it reads and writes; empy's stdout proxy rules out redirecting it)
                idl_file = convert_msg_to_idl(package_dir, PACKAGE, f.relative_to(package_dir), idl_root / "msg")
                content = parse_idl_file(definition.IdlLocator(idl_root, idl_file.relative_to(idl_root))).content
            except Exception as error:  # noqa: BLE001  (any refusal by rosidl is the finding)
                problems.append(f"rosidl refused msg/{f.name}: {type(error).__name__}: {error}")
                continue
            found = content.get_elements_of_type(definition.Message)
            if len(found) != 1:
                problems.append(f"msg/{f.name}: rosidl found {len(found)} messages, expected 1")
                continue
            message = found[0]
            if list(message.structure.namespaced_type.namespaced_name()) != [PACKAGE, "msg", f.stem]:
                problems.append(f"msg/{f.name}: rosidl named it {message.structure.namespaced_type.namespaced_name()}")
            fields = [(type_name(m.type), m.name) for m in message.structure.members]
            codes = [(type_name(c.type), c.name, c.value) for c in message.constants]
            parsed[f.stem] = (fields, codes)
    return parsed


def compare(idl_file, package_dir):
    """Problems found in package_dir against idl_file, one line each."""
    problems = []
    structs, constants = idl_structs.parse_all(idl_file.read_text())
    want = expected_messages(structs, constants)
    got = parse_with_rosidl(package_dir, problems)
    for name in sorted(set(want) - set(got)):
        if not any(p.startswith(f"rosidl refused msg/{name}.msg") for p in problems):
            problems.append(f"no msg/{name}.msg for struct {PACKAGE}::msg::dds_::{name}_")
    for name in sorted(set(got) - set(want)):
        problems.append(f"msg/{name}.msg has no struct {name}_ in the IDL")
    for name in sorted(set(want) & set(got)):
        (want_fields, want_codes), (got_fields, got_codes) = want[name], got[name]
        if got_fields != want_fields:
            problems.append(f"msg/{name}.msg fields: IDL {want_fields}, rosidl {got_fields}")
        if got_codes != want_codes:
            problems.append(f"msg/{name}.msg constants: IDL {want_codes}, rosidl {got_codes}")

    for required in ("package.xml", "CMakeLists.txt", "README.md", "msg_files.cmake"):
        if not (package_dir / required).is_file():
            problems.append(f"the package has no {required}")
    if (package_dir / "package.xml").is_file():
        root = ElementTree.parse(package_dir / "package.xml").getroot()
        if root.findtext("name") != PACKAGE:
            problems.append(f"package.xml names {root.findtext('name')!r}, not {PACKAGE}")
        if root.findtext("member_of_group") != "rosidl_interface_packages":
            problems.append("package.xml: not a member of rosidl_interface_packages")
    if (package_dir / "msg_files.cmake").is_file():
        listed = re.findall(r'"msg/(\w+\.msg)"', (package_dir / "msg_files.cmake").read_text())
        present = sorted(f.name for f in (package_dir / "msg").glob("*.msg"))
        if sorted(listed) != present:
            problems.append(f"msg_files.cmake lists {sorted(listed)}, msg/ holds {present}")
    return problems, want


def mutation_caught(idl_file, package_dir, mutate):
    """True when compare() finds a problem in a copy of the package changed by mutate(msg_dir)."""
    with tempfile.TemporaryDirectory() as tmp:
        copy = pathlib.Path(tmp) / PACKAGE
        shutil.copytree(package_dir, copy)
        mutate(copy / "msg")
        return bool(compare(idl_file, copy)[0])


def drop_line(path, pattern):
    lines = path.read_text().splitlines(keepends=True)
    index = next(i for i, line in enumerate(lines) if re.match(pattern, line))
    path.write_text("".join(lines[:index] + lines[index + 1:]))


def main():
    if len(sys.argv) != 3:
        raise SystemExit("usage: check_msg_package.py IDL_FILE PACKAGE_DIR")
    idl_file, package_dir = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2]).resolve()
    if not (package_dir / "msg").is_dir():
        print(f"{package_dir}/msg does not exist: build the project first (target crane_msgs_ros2_package)")
        return 1
    problems, want = compare(idl_file, package_dir)
    mutations = {
        "SensorSample.msg without its field cable_length":
            lambda d: drop_line(d / "SensorSample.msg", r"float64 cable_length\b"),
        "SupervisorStatus.msg with STAGES_ALL=62":
            lambda d: (d / "SupervisorStatus.msg").write_text(
                re.sub(r"STAGES_ALL=\d+", "STAGES_ALL=62", (d / "SupervisorStatus.msg").read_text())),
    }
    if not problems:
        for what, mutate in mutations.items():
            if not mutation_caught(idl_file, package_dir, mutate):
                problems.append(f"the check did not notice {what}")
    for p in problems:
        print(p)
    fields = sum(len(f) for f, _ in want.values())
    codes = sum(len(c) for _, c in want.values())
    print(f"{len(want)} messages ({fields} fields, {codes} constants) parsed by rosidl and compared with the IDL, "
          f"{len(mutations)} mutations checked: {len(problems)} problems")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
