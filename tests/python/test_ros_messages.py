"""ros/tumble_msgs (a ROS 2 package of .msg files) defines, field for field and type for type, the
structs of module tumble_msgs in proto/dds/tumble_states.idl that the server publishes: a ROS 2
workspace that builds it decodes rt/tumble/pose_ids, contacts, stats and bodies. (ROS 2 names a
message pkg/msg/Name on DDS pkg::msg::dds_::Name_, so the package name is the IDL module's.)"""

import os
import re

SOURCE = os.environ["TUMBLE_SOURCE_DIR"]
ROS_TYPES = {"uint8": "uint8", "uint32": "uint32", "uint64": "uint64", "int32": "int32",
             "float32": "float", "float64": "double", "bool": "boolean", "string": "string"}


def idl_structs(module):
    with open(os.path.join(SOURCE, "proto", "dds", "tumble_states.idl")) as file:
        text = re.sub(r"//[^\n]*", "", file.read())
    body = text[text.index(f"module {module} {{"):]
    structs = {}
    for name, fields in re.findall(r"struct (\w+)_ \{(.*?)\};", body, re.S):
        members = []
        for field in fields.split(";"):
            field = re.sub(r"@key\s+", "", " ".join(field.split()))
            if field:
                kind, member = field.rsplit(" ", 1)
                members.append((member, kind))
        structs[name] = members
        if name == "Body":
            break
    return structs


def msg_fields(path):
    members = []
    with open(path) as file:
        for line in file:
            line = line.split("#")[0].strip()
            if not line or "=" in line:  # blank, or a constant
                continue
            kind, member = line.split()
            array = re.fullmatch(r"(.+)\[(\d*)\]", kind)
            base = array.group(1) if array else kind
            if "/" in base:
                package, name = base.split("/")
                base = f"{package}::msg::dds_::{name}_"
            else:
                base = ROS_TYPES[base]
            if array and array.group(2):
                members.append((f"{member}[{array.group(2)}]", base))
            elif array:
                members.append((member, f"sequence<{base}>"))
            else:
                members.append((member, base))
    return members


def test_the_ros_package_defines_the_idl_types_field_for_field():
    structs = idl_structs("tumble_msgs")
    assert sorted(structs) == ["Body", "BodyIds", "BodyPart", "Contacts", "StepStats"]
    directory = os.path.join(SOURCE, "ros", "tumble_msgs", "msg")
    assert sorted(os.listdir(directory)) == sorted(f"{name}.msg" for name in structs)
    for name, members in structs.items():
        assert msg_fields(os.path.join(directory, f"{name}.msg")) == members, name
    with open(os.path.join(SOURCE, "ros", "tumble_msgs", "package.xml")) as file:
        assert "<name>tumble_msgs</name>" in file.read()
