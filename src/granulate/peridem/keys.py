"""The keys of PeriDEM decks granulate reads, block by block, and its output tags."""

from __future__ import annotations

#: Sections of a deck and the keys granulate reads in each (Zone_<k> / Set_<s> blocks apart).
SECTIONS = (
    "Model",
    "Zone",
    "Particle",
    "Particle_Generation",
    "Mesh",
    "Material",
    "Contact",
    "Neighbor",
    "Force_BC",
    "Displacement_BC",
    "IC",
    "Output",
    "Restart",
    "Wall",
)
#: Top-level keys PeriDEM does not read (or that only describe the set-up).
IGNORED_SECTIONS = ("HPX", "Policy", "Container", "State_Potential")

MODEL_KEYS = {
    "Dimension",
    "Discretization_Type",
    "Final_Time",
    "Time_Steps",
    "Particle_Sim_Type",
    "Seed",
    "Horizon",
    "Mesh_Size",
    "Horizon_h_Ratio",
}
PARTICLE_ZONE_KEYS = {
    "Type",
    "Parameters",
    "Is_Wall",
    "All_Dofs_Constrained",
    "Create_Particle_Using_ParticleZone_GeomObject",
    "Vec_Type",
    "Vec_Flag",
}
MATERIAL_KEYS = {
    "Type",
    "Density",
    "Horizon",
    "Horizon_Mesh_Ratio",
    "Compute_From_Classical",
    "E",
    "K",
    "G",
    "Poisson_Ratio",
    "Gc",
    "KIc",
    "Influence_Function",
    "Copy_Material_Data",
    "Is_Plane_Strain",
}
CONTACT_KEYS = {
    "Contact_Radius_Factor",
    "Contact_Radius",
    "Kn",
    "Kn_Factor",
    "Damping_On",
    "Epsilon",
    "Beta_n_Factor",
    "Friction_On",
    "Friction_Coeff",
    "Copy_Contact_Data",
}
SET_KEYS = {
    "Particle_List",
    "Wall_List",
    "Particle_Exclude_List",
    "Region",
    "Direction",
    "Zero_Displacement",
    "Time_Function",
    "Spatial_Function",
}
OUTPUT_KEYS = {
    "Path",
    "Tags",
    "Output_Interval",
    "Test_Output_Interval",
    "Perform_Out",
    "Perform_FE_Out",
    "Output_Criteria",
    "Compress_Type",
    "File_Format",
    "Debug",
    "Tag_PP",
}
#: PeriDEM output tags -> granulate output fields.
TAGS = {
    "Displacement": "Displacement",
    "Velocity": "Velocity",
    "Force": "Force",
    "Force_Density": "Force_Density",
    "Damage_Z": "Damage_Z",
    "Damage": "Damage",
    "Nodal_Volume": "Nodal_Volume",
    "Particle_ID": "Particle_ID",
    "Fixity": "Fixity",
    "Theta": "Dilatation",
}
#: Tags granulate does not write (reported, the run goes on).
UNWRITTEN_TAGS = (
    "Contact_Data",
    "Zone_ID",
    "Force_Fixity",
    "Contact_Nodes",
    "No_Fail_Node",
    "Boundary_Node_Flag",
    "Strain_Stress",
    "Particle_Locations",
)
