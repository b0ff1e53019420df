"""The warm-start search tree over the periodic grid graph."""

from hypothesis import given
from hypothesis import strategies as st

from flatcontact.ispes.order import depth, neighbours, search_tree


def _adjacent(p, q, shape):
    d = [abs(x - y) for x, y in zip(p, q, strict=True)]
    lateral = [min(d[k], shape[k] - d[k]) for k in (0, 1)]
    return sorted([*lateral, d[2]]) == [0, 0, 1]


@given(
    st.integers(1, 6),
    st.integers(1, 6),
    st.integers(1, 5),
    st.sampled_from(["columns", "planes"]),
    st.data(),
)
def test_tree_spans_the_grid_with_neighbour_parents(na, nb, nz, prefer, data):
    shape = (na, nb, nz)
    root = (
        data.draw(st.integers(0, na - 1)),
        data.draw(st.integers(0, nb - 1)),
        data.draw(st.integers(0, nz - 1)),
    )
    parent = search_tree(shape, root, prefer)
    assert len(parent) == na * nb * nz
    seen = set()
    for node, par in parent.items():  # visiting order: a parent always comes before its children
        if par is None:
            assert node == root
        else:
            assert par in seen and _adjacent(node, par, shape)
        seen.add(node)
    # breadth-first: the depth is the graph eccentricity of the root
    ecc = max(
        min(abs(a - root[0]), na - abs(a - root[0]))
        + min(abs(b - root[1]), nb - abs(b - root[1]))
        + abs(z - root[2])
        for (a, b, z) in parent
    )
    assert depth(parent) == ecc + 1


def test_lateral_neighbours_wrap_around_the_cell():
    assert set(neighbours((0, 0, 0), (4, 3, 2))) == {
        (3, 0, 0),
        (1, 0, 0),
        (0, 2, 0),
        (0, 1, 0),
        (0, 0, 1),
    }


def test_preferences_choose_different_parents():
    shape = (3, 3, 3)
    planes = search_tree(shape, (0, 0, 1), "planes")
    columns = search_tree(shape, (0, 0, 1), "columns")
    # off the root column, "planes" spreads each plane laterally; off the root plane,
    # "columns" walks each column along z
    assert planes[(1, 0, 2)] == (0, 0, 2)
    assert columns[(1, 0, 2)] == (1, 0, 1)
    cold = search_tree(shape, (0, 0, 1), "cold")
    assert all(p is None for p in cold.values()) and len(cold) == 27
