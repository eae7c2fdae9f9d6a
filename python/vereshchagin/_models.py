"""Python-side members of the compiled Chain and Tree (``python/bindings/model_bindings.cpp``): their repr."""

from __future__ import annotations

from ._core import Chain, Tree


def _chain_repr(self: Chain) -> str:
    """``<vereshchagin.Chain with 7 segments, 7 joints>``."""
    return f"<vereshchagin.Chain with {self.n_segments} segments, {self.n_joints} joints>"


def _tree_repr(self: Tree) -> str:
    """``<vereshchagin.Tree with 19 segments, 19 joints, base 'base'>``."""
    return f"<vereshchagin.Tree with {self.n_segments} segments, {self.n_joints} joints, base '{self.root_link}'>"


# setattr because a type checker rejects assigning to a declared method.
setattr(Chain, "__repr__", _chain_repr)  # noqa: B010
setattr(Tree, "__repr__", _tree_repr)  # noqa: B010
