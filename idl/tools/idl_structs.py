"""Parser of the struct subset of IDL that idl/crane_msgs.idl uses (ROS 2 style, fixed size).

One parser for every tool that reads the IDL: the build-time generators (gen_cyclone_support.py,
gen_protocol.py) and the check of the generated ROS 2 package (tests/ros2/check_msg_package.py).

Supported: nested modules, `@final struct Name { TYPE name; TYPE name[N]; };` with primitive
types and other structs of the file, and integer constants `const TYPE NAME = VALUE;` in a module
`<Struct>_Constants` beside the struct's module (rosidl's layout for a .msg's constants).
Anything else is refused with the declaration quoted.
"""
import re

PRIMITIVES = {"double", "float", "boolean", "octet", "char", "int8", "uint8", "int16", "uint16", "int32",
              "uint32", "int64", "uint64"}


class Field:
    def __init__(self, idl_type, name, size):
        self.idl_type = idl_type  # primitive name or the struct's name without modules ("Time_")
        self.name = name
        self.size = size          # array length, or None
        self.comment = ""         # the IDL's trailing comment of the declaration (units, meaning)
        self.leading = []         # whole-line comments right above the declaration

    @property
    def primitive(self):
        return self.idl_type in PRIMITIVES


class Constant:
    def __init__(self, modules, idl_type, name, value):
        self.modules = modules    # ["crane_msgs", "msg", "SupervisorStatus_Constants"]
        self.idl_type = idl_type  # integer primitive
        self.name = name          # "FAULT_STAGE_SILENT"
        self.value = value        # int
        self.comment = ""         # the IDL's trailing comment of the declaration
        self.leading = []         # whole-line comments right above the declaration

    @property
    def owner(self):              # the struct the constant belongs to, without the trailing _: "SupervisorStatus"
        return self.modules[-1][:-len("_Constants")]

    @property
    def group(self):              # "FAULT" of FAULT_STAGE_SILENT: constants of one group are one code
        return self.name.split("_", 1)[0]

    @property
    def member(self):             # "stage_silent": the name of the value within its group
        return self.name.split("_", 1)[1].lower() if "_" in self.name else self.name.lower()


class Struct:
    def __init__(self, modules, name, fields):
        self.modules = modules    # ["crane_msgs", "msg", "dds_"]
        self.name = name          # "SensorSample_"
        self.fields = fields      # [Field]
        self.leading = []         # whole-line comments right above the struct (and its annotations)

    @property
    def scoped_name(self):        # crane_msgs::msg::dds_::SensorSample_ (C++ class, DDS type name)
        return "::".join(self.modules + [self.name])

    @property
    def c_name(self):             # crane_msgs_msg_dds__SensorSample_ (idlc's C struct)
        return "_".join(self.modules + [self.name])


def parse(text):
    """[Struct] in file order. Raises SystemExit naming an unparsed declaration."""
    return parse_all(text)[0]


def parse_all(text):
    """([Struct], [Constant]) in file order. Raises SystemExit naming an unparsed declaration."""
    # Comments, by a line-wise pass: trailing comments (and their continuation lines, aligned under
    # them) of fields and constants, and the whole-line comments right above a struct, a field or a
    # constant. Keys: ("field", struct, name), ("const", module, name), ("struct", name).
    comments = {}
    leading = {}
    pending = []   # whole-line comments not yet attached
    current = None
    module = None
    last = None
    for line in text.splitlines():
        s = re.match(r"\s*(?:@\w+\s*)*struct\s+(\w+)", line)
        mod = re.match(r"\s*module\s+(\w+)", line)
        d = re.match(r"\s*[\w:]+\s+(\w+)(?:\[\d+\])?\s*;\s*(?://\s*(.*))?$", line)
        c = re.match(r"\s*const\s+\w+\s+(\w+)\s*=\s*[^;]+;\s*(?://\s*(.*))?$", line)
        full = re.match(r"\s*//\s?(.*)$", line)
        if s:
            current, last = s.group(1), None
            leading[("struct", current)], pending = pending, []
        elif mod:
            module, current, last, pending = mod.group(1), None, None, []
        elif (d and current) or c:
            last = ("field", current, d.group(1)) if d and current else ("const", module, c.group(1))
            comments[last] = ((d or c).group(2) or "").strip()
            leading[last], pending = pending, []
        elif full and last and comments.get(last) and len(line) - len(line.lstrip()) > 20:
            comments[last] += " " + full.group(1).strip()  # a continuation aligned under the comment
        elif full:
            pending.append(full.group(1).rstrip())
            last = None
        elif re.fullmatch(r"\s*(?:@\w+(?:\([^)]*\))?\s*)+", line):
            pass  # an annotation line between a comment and its struct
        else:
            last, pending = None, []
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    structs = []
    constants = []
    known = set()
    modules = []
    depth_of_module = []
    depth = 0
    pos = 0
    token = re.compile(r"module\s+(\w+)\s*\{|(?:@\w+\s*)*struct\s+(\w+)\s*\{(.*?)\}\s*;"
                       r"|const\s+(\w+)\s+(\w+)\s*=\s*([^;]+);|\{|\}", re.S)
    while True:
        m = token.search(text, pos)
        if not m:
            break
        pos = m.end()
        if m.group(1):
            modules.append(m.group(1))
            depth += 1
            depth_of_module.append(depth)
        elif m.group(2):
            fields = []
            for decl in m.group(3).split(";"):
                decl = " ".join(decl.split())
                if not decl:
                    continue
                d = re.fullmatch(r"([\w:]+)\s+(\w+)(?:\[(\d+)\])?", decl)
                if not d:
                    raise SystemExit(f"unparsed IDL declaration in {m.group(2)}: {decl!r}")
                idl_type, name, size = d.groups()
                base = idl_type.split("::")[-1]
                if idl_type not in PRIMITIVES and base not in known:
                    raise SystemExit(f"unknown IDL type {idl_type} in {m.group(2)}")
                fields.append(Field(idl_type if idl_type in PRIMITIVES else base, name,
                                    int(size) if size else None))
            structs.append(Struct(list(modules), m.group(2), fields))
            known.add(m.group(2))
        elif m.group(4):
            if not modules or not modules[-1].endswith("_Constants"):
                raise SystemExit(f"constant {m.group(5)} outside a <Struct>_Constants module")
            if m.group(4) not in PRIMITIVES or m.group(4) in ("double", "float", "boolean", "char"):
                raise SystemExit(f"constant {m.group(5)}: only integer constants are supported, not {m.group(4)}")
            value = m.group(6).strip()
            if not re.fullmatch(r"-?(0x[0-9a-fA-F]+|\d+)", value):
                raise SystemExit(f"constant {m.group(5)}: value {value!r} is not an integer literal")
            constants.append(Constant(list(modules), m.group(4), m.group(5), int(value, 0)))
        elif m.group(0) == "{":
            depth += 1
        else:
            if depth_of_module and depth_of_module[-1] == depth:
                depth_of_module.pop()
                modules.pop()
            depth -= 1
    for s in structs:
        s.leading = leading.get(("struct", s.name), [])
        for f in s.fields:
            f.comment = comments.get(("field", s.name, f.name), "")
            f.leading = leading.get(("field", s.name, f.name), [])
    for c in constants:
        c.comment = comments.get(("const", c.modules[-1], c.name), "")
        c.leading = leading.get(("const", c.modules[-1], c.name), [])
    owners = {s.name[:-1] for s in structs}
    for c in constants:
        if c.owner not in owners:
            raise SystemExit(f"constant {c.name}: module {c.modules[-1]} names no struct {c.owner}_")
    return structs, constants
