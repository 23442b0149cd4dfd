"""Parser of the struct subset of IDL that idl/crane_msgs.idl uses (ROS 2 style, fixed size).

One parser for every tool that reads the IDL: the build-time generator of the Cyclone DDS type
support (gen_cyclone_support.py) and the checks of tests/ros2 (check_msgs.py).

Supported: nested modules, `@final struct Name { TYPE name; TYPE name[N]; };` with primitive
types and other structs of the file. Anything else is refused with the declaration quoted.
"""
import re

PRIMITIVES = {"double", "float", "boolean", "octet", "char", "int8", "uint8", "int16", "uint16", "int32",
              "uint32", "int64", "uint64"}


class Field:
    def __init__(self, idl_type, name, size):
        self.idl_type = idl_type  # primitive name or the struct's name without modules ("Time_")
        self.name = name
        self.size = size          # array length, or None

    @property
    def primitive(self):
        return self.idl_type in PRIMITIVES


class Struct:
    def __init__(self, modules, name, fields):
        self.modules = modules    # ["crane_msgs", "msg", "dds_"]
        self.name = name          # "SensorSample_"
        self.fields = fields      # [Field]

    @property
    def scoped_name(self):        # crane_msgs::msg::dds_::SensorSample_ (C++ class, DDS type name)
        return "::".join(self.modules + [self.name])

    @property
    def c_name(self):             # crane_msgs_msg_dds__SensorSample_ (idlc's C struct)
        return "_".join(self.modules + [self.name])


def parse(text):
    """[Struct] in file order. Raises SystemExit naming an unparsed declaration."""
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    structs = []
    known = set()
    modules = []
    depth_of_module = []
    depth = 0
    pos = 0
    token = re.compile(r"module\s+(\w+)\s*\{|(?:@\w+\s*)*struct\s+(\w+)\s*\{(.*?)\}\s*;|\{|\}", re.S)
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
        elif m.group(0) == "{":
            depth += 1
        else:
            if depth_of_module and depth_of_module[-1] == depth:
                depth_of_module.pop()
                modules.pop()
            depth -= 1
    return structs
