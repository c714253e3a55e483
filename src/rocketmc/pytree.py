"""One rule for parameter and state containers (see docs/conventions.md).

Every container is a frozen dataclass registered as a JAX pytree. Array-valued fields are
*dynamic*: they can be batched by ``vmap`` and dispersed. Python ints, bools, strings, enumerations and tuples
that set shapes or choose code paths are *static*: mark them ``static_field()``; changing one
recompiles.
"""

from __future__ import annotations

import dataclasses

import jax
import jax.numpy as jnp


def pytree_dataclass(cls):
    """Decorate ``cls`` as a frozen dataclass registered as a JAX pytree."""
    return jax.tree_util.register_dataclass(dataclasses.dataclass(frozen=True)(cls))


def static_field(**kwargs):
    """A dataclass field that is part of the pytree's structure, not of its leaves."""
    return dataclasses.field(metadata={"static": True}, **kwargs)


def tree_where(condition, if_true, if_false):
    """Element-wise ``if_true if condition else if_false`` over two pytrees of the same structure."""
    return jax.tree_util.tree_map(lambda a, b: jnp.where(condition, a, b), if_true, if_false)
