# Node groups seen as one flat node tree, as Cycles flattens them (intern/cycles/blender/shader.cpp
# replaces each group by its contents, with proxies for the group's inputs and outputs).
#
# Sockets and nodes are wrapped with the path of group nodes they sit in (`ctx`, outermost
# first). Following a link into a Group node continues from the group's active Group Output;
# following a link from a Group Input continues from the enclosing Group node's input. A socket
# that ends unlinked takes its value from the last group boundary it crossed (the Group node's
# input, or the Group Output's input), as Cycles' proxies do. Reroutes and muted nodes are
# followed through their pass-through links. Translators use wrapped sockets and nodes as they
# would use Blender's: `is_linked`, `default_value` and `name` are the flattened tree's.

_MAX_HOPS = 256  # links followed for one socket (a guard against cyclic groups)


def wrap(socket):
    """The top-level (not inside any group) wrapper of a Blender socket."""
    return socket if isinstance(socket, Sock) else Sock(socket, ())


class Node:
    __slots__ = ("node", "ctx", "type")

    def __init__(self, node, ctx):
        self.node = node
        self.ctx = ctx
        self.type = node.type  # read for every node visited: kept, not looked up again

    def __getattr__(self, key):
        return getattr(self.node, key)

    def __eq__(self, other):
        return isinstance(other, Node) and self.node == other.node and self.ctx == other.ctx

    def __hash__(self):
        return hash((self.node.as_pointer(), tuple(g.as_pointer() for g in self.ctx)))

    @property
    def name(self):
        """Unique in the flattened tree: the group nodes' names, then the node's."""
        if not self.ctx:
            return self.node.name
        return "/".join([g.name for g in self.ctx] + [self.node.name])

    @property
    def inputs(self):
        return _Sockets(self.node.inputs, self.ctx)

    @property
    def outputs(self):
        return _Sockets(self.node.outputs, self.ctx, output=True)

    def passthrough(self, output):
        """The input a muted node or reroute passes to `output` (a Sock), or None."""
        for link in self.node.internal_links:
            if link.to_socket == output.socket:
                return Sock(link.from_socket, self.ctx)
        if self.node.type == 'REROUTE':
            return Sock(self.node.inputs[0], self.ctx)
        return None


class _Sockets:
    __slots__ = ("sockets", "ctx", "output")

    def __init__(self, sockets, ctx, output=False):
        self.sockets = sockets
        self.ctx = ctx
        self.output = output

    def __getitem__(self, key):
        return Sock(self.sockets[key], self.ctx, self.output)

    def __len__(self):
        return len(self.sockets)

    def __iter__(self):
        return (Sock(s, self.ctx, self.output) for s in self.sockets)

    def get(self, key):
        s = self.sockets.get(key)
        return None if s is None else Sock(s, self.ctx, self.output)


class Sock:
    __slots__ = ("socket", "ctx", "_followed")

    def __init__(self, socket, ctx, output=False):
        self.socket = socket
        self.ctx = ctx
        self._followed = (None, self) if output else None  # an output feeds, is not fed

    def __getattr__(self, key):
        return getattr(self.socket, key)

    def __eq__(self, other):
        return isinstance(other, Sock) and self.socket == other.socket and self.ctx == other.ctx

    def __hash__(self):
        return hash((self.socket.as_pointer(), tuple(g.as_pointer() for g in self.ctx)))

    @property
    def node(self):
        return Node(self.socket.node, self.ctx)

    def follow(self):
        """(output Sock feeding this input in the flattened tree or None, the Sock whose
        default_value stands for it when None)."""
        if self._followed is None:
            self._followed = _follow(self)
        return self._followed

    @property
    def is_linked(self):
        return self.follow()[0] is not None

    @property
    def default_value(self):
        return converted(self.follow()[1].socket, self.socket.type)


# Cycles' implicit conversions when a group socket's value reaches an input of another type.
_LUMINANCE = (0.2126, 0.7152, 0.0722)


def converted(source, to_type):
    """`source`'s default_value as an input of type `to_type` reads it (a float group input
    feeding a Mapping's Scale, a colour feeding a Math node...)."""
    value = source.default_value
    kind = source.type
    if kind == to_type or to_type not in {'VALUE', 'INT', 'VECTOR', 'RGBA'}:
        return value
    if kind in {'VALUE', 'INT'}:
        v = float(value)
        return (v, v, v) if to_type == 'VECTOR' else (v, v, v, 1.0) if to_type == 'RGBA' else v
    if kind == 'VECTOR':
        x, y, z = value
        return (x, y, z, 1.0) if to_type == 'RGBA' else (x + y + z) / 3.0
    if kind == 'RGBA':
        r, g, b = tuple(value)[:3]
        if to_type == 'VECTOR':
            return (r, g, b)
        return sum(w * c for w, c in zip(_LUMINANCE, (r, g, b)))
    return value


def source(socket):
    """The output socket (a Sock) feeding `socket` in the flattened tree, None if unlinked."""
    return wrap(socket).follow()[0]


def _group_output(tree):
    outputs = [n for n in tree.nodes if n.type == 'GROUP_OUTPUT']
    for n in outputs:
        if n.is_active_output:
            return n
    return outputs[0] if outputs else None


def _by_identifier(sockets, identifier):
    for s in sockets:
        if s.identifier == identifier:
            return s
    return None


# Node tree pointer -> {input socket pointer: the link into it}, for the export under way
# (Blender's socket.links scans all of the tree's links at every call).
_links = {}


def reset():
    """Forgets the link tables: call at the start of each export (trees may have changed)."""
    _links.clear()


def _link_into(socket):
    tree = socket.id_data
    table = _links.get(tree.as_pointer())
    if table is None:
        table = {link.to_socket.as_pointer(): link for link in tree.links}
        _links[tree.as_pointer()] = table
    return table.get(socket.as_pointer())


def _follow(start):
    sock, holder = start, start
    for _ in range(_MAX_HOPS):
        link = _link_into(sock.socket)
        if link is None:
            return None, holder
        if not link.is_valid or link.is_muted:
            return None, holder
        out, node, ctx = link.from_socket, link.from_node, sock.ctx
        if node.type == 'REROUTE' or node.mute:
            through = Node(node, ctx).passthrough(Sock(out, ctx, output=True))
            if through is None:
                return None, holder
            sock = through
        elif node.type == 'GROUP':
            tree = node.node_tree
            group_out = _group_output(tree) if tree is not None else None
            inner = _by_identifier(group_out.inputs, out.identifier) if group_out else None
            if inner is None:
                return None, holder
            sock = holder = Sock(inner, ctx + (node,))
        elif node.type == 'GROUP_INPUT':
            if not ctx:
                return None, holder
            outer = _by_identifier(ctx[-1].inputs, out.identifier)
            if outer is None:
                return None, holder
            sock = holder = Sock(outer, ctx[:-1])
        else:
            return Sock(out, ctx, output=True), holder
    return None, holder
