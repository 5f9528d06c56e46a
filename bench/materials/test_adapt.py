# Checks adapt.py's loading of Blender 4.x Node-To-Python scripts without Blender: sockets found by
# their Blender 4 name, what 3.4 lacks skipped and listed, links to it dropped.
#   python3 bench/materials/test_adapt.py
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import adapt  # noqa: E402


class Sockets(list):
    def __contains__(self, name):
        return any(s.name == name for s in self)

    def __getitem__(self, key):
        if isinstance(key, str):
            return next(s for s in self if s.name == key)
        return list.__getitem__(self, key)


class Socket:
    def __init__(self, name, value=0.0):
        self.name, self.default_value = name, value


class Node:
    LAYOUT = {"ShaderNodeTexNoise": ["Vector", "W", "Scale", "Detail", "Roughness", "Distortion"],
              "ShaderNodeMath": ["Value", "Value_001", "Value_002"]}

    def __init__(self, kind):
        self.bl_idname, self.name = kind, kind
        self.inputs = Sockets(Socket(n) for n in self.LAYOUT[kind])
        self.outputs = Sockets([Socket("Fac"), Socket("Color")])


class Tree:
    def __init__(self):
        self.nodes, self.links = self, self
        self.made = []

    def new(self, a, b=None):
        if b is None:
            return Node(a)
        self.made.append((a.name, b.name))
        return (a, b)


SCRIPT = """
noise = tree.nodes.new("ShaderNodeTexNoise")
noise.inputs[2].default_value = 5.0
noise.inputs[8].default_value = 0.7
noise.inputs[6].default_value = 0.3
noise.noise_type = 'FBM'
math = tree.nodes.new("ShaderNodeMath")
tree.links.new(noise.outputs[0], math.inputs[1])
tree.links.new(noise.outputs[1], math.inputs[7])
noise.inputs["Gain"].default_value = 2.0
tree.links.new(noise.outputs["Color"], math.inputs["Value"])
"""


def main():
    tree, log = Tree(), []
    env = {"tree": tree, "_socket": lambda n, k, i: adapt.socket(log, n, k, i),
           "_assign": lambda t, a, v: adapt.assign(log, t, a, v),
           "_named": lambda n, k, name: adapt.named_socket(log, n, k, name),
           "_link": lambda t, a, b: adapt.link(log, t, a, b)}
    exec(adapt.rewrite(SCRIPT), env)
    noise = env["noise"]
    values = {s.name: s.default_value for s in noise.inputs}
    assert values["Scale"] == 5.0, values
    assert values["Distortion"] == 0.7, values  # input 8 in Blender 4.x, 5 in 3.4
    assert values["Roughness"] == 0.0 and values["Detail"] == 0.0, values  # Offset (6) skipped
    assert tree.made == [("Fac", "Value_001"), ("Color", "Value")], tree.made
    assert any("'Gain' missing" in m for m in log), log
    assert any("input 6" in m for m in log), log
    assert any("inputs[7]" in m and "dropped" in m for m in log), log
    print("ok: adapt maps Blender 4.x sockets by name and lists", len(log), "skipped settings")


main()
