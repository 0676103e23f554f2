"""The package's face: every public name is documented, and the type hints (.pyi) declare it
with the parameters it really takes."""
import ast
import inspect
import unittest
from pathlib import Path

import fleetmap

PYI = Path(fleetmap.__file__).with_suffix(".pyi")


def pyi_definitions():
    tree = ast.parse(PYI.read_text())
    return {node.name: node for node in tree.body if isinstance(node, (ast.FunctionDef, ast.ClassDef))}


def pyi_parameters(node):
    args = node.args
    names = [a.arg for a in args.posonlyargs + args.args]
    names += [args.vararg.arg] if args.vararg else []
    names += [a.arg for a in args.kwonlyargs]
    return names + ([args.kwarg.arg] if args.kwarg else [])


class ApiTest(unittest.TestCase):
    def test_every_public_name_has_a_docstring(self):
        for name in fleetmap.__all__:
            obj = getattr(fleetmap, name)
            doc = inspect.getdoc(obj) or ""
            # pybind11 puts the signature first; a docstring is more than that.
            lines = [line for line in doc.splitlines() if line.strip() and not line.startswith(name + "(")]
            self.assertTrue(lines, f"{name} has no docstring")
            if inspect.isclass(obj):
                for member, value in vars(obj).items():
                    if member.startswith("_"):
                        continue
                    member_doc = inspect.getdoc(value) or ""
                    lines = [line for line in member_doc.splitlines()
                             if line.strip() and not line.startswith(member + "(")]
                    self.assertTrue(lines, f"{name}.{member} has no docstring")

    def test_the_pyi_declares_every_public_name_with_its_parameters(self):
        declared = pyi_definitions()
        for name in fleetmap.__all__:
            self.assertIn(name, declared, f"{name} is not in {PYI.name}")
            obj = getattr(fleetmap, name)
            if inspect.isfunction(obj):  # the Python half: its real signature
                self.assertEqual(pyi_parameters(declared[name]), list(inspect.signature(obj).parameters),
                                 f"{name}'s parameters differ from {PYI.name}")


if __name__ == "__main__":
    unittest.main()
