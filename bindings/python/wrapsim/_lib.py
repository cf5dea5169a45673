"""Low level: the ctypes mirror of include/wrapsim/*.h and the loader of libwrapsim.

Every struct below mirrors its C struct field by field (same order, same types); every public
function of the library is in FUNCTIONS, one row (name, argtypes, restype) each. Enums cross the
boundary as C int.
"""

import ctypes
import ctypes.util
import os
import pathlib
import sys
from ctypes import (CFUNCTYPE, POINTER, Structure, c_char, c_char_p, c_double, c_int, c_int32,
                    c_int64, c_size_t, c_uint, c_uint8, c_uint32, c_uint64, c_void_p)

#: The oldest library this binding works with: major * 10000 + minor * 100 + patch.
REQUIRED_VERSION = 100  # 0.1.0
#: The binding's own version.
BINDING_VERSION = "0.1.0"

# --- enums (common.h, world.h, body.h, contact.h, law.h, web.h, element.h) ----------------------
WS_OK = 0
WS_ERR_INVALID_ARGUMENT = 1
WS_ERR_UNINITIALIZED_DEF = 2
WS_ERR_STALE_HANDLE = 3
WS_ERR_OUT_OF_MEMORY = 4
WS_ERR_NUMERICAL = 5
WS_ERR_BAD_MESH = 6
WS_ERR_IN_USE = 7
WS_ERR_CALLBACK = 8
WS_ERR_BUFFER_TOO_SMALL = 9
WS_ERR_IO = 10
WS_ERR_UNSUPPORTED = 11
WS_ERR_IN_STEP = 12
WS_ERR_FORMAT = 13

WS_LOG_DEBUG, WS_LOG_INFO, WS_LOG_WARNING, WS_LOG_ERROR = 0, 1, 2, 3
WS_FEATURE_CCD = 1
WS_FEATURE_ZLIB = 2
WS_INTEGRATOR_SYMPLECTIC_EULER, WS_INTEGRATOR_PAPER_EXPLICIT = 0, 1
WS_FRICTION_REGULARIZED, WS_FRICTION_STICK = 0, 1
WS_FRICTION_STEP_IMPLICIT, WS_FRICTION_STEP_EXPLICIT = 0, 1
WS_BODY_DYNAMIC, WS_BODY_KINEMATIC = 0, 1
WS_DRIVE_STATIC, WS_DRIVE_TILT, WS_DRIVE_SINE, WS_DRIVE_CALLBACK = 0, 1, 2, 3
WS_DRIVE_PULSE, WS_DRIVE_IMPACT, WS_DRIVE_TABLE, WS_DRIVE_RANDOM, WS_DRIVE_SWEEP = 4, 5, 6, 7, 8
WS_PULSE_ACCELERATE, WS_PULSE_BRAKE = 0, 1
WS_SWEEP_LOG, WS_SWEEP_LINEAR = 0, 1
WS_TRUCK_LOW, WS_TRUCK_MEDIUM, WS_TRUCK_HIGH = 1, 2, 3
WS_STANDARD_GRAVITY = 9.80665
WS_CONTACT_POINT_FACE, WS_CONTACT_EDGE_EDGE, WS_CONTACT_FACE_POINT = 0, 1, 2
WS_LAW_LINEAR_ELASTIC, WS_LAW_LINEAR_VISCOELASTIC, WS_LAW_TENSION_COMPRESSION = 0, 1, 2
WS_LAW_LINEAR_VISCOUS, WS_LAW_CUBIC_ELASTIC, WS_LAW_TABLE, WS_LAW_STOP = 3, 4, 5, 6
WS_LAW_RELAXATION, WS_LAW_SUM, WS_LAW_SCALED, WS_LAW_USER = 7, 8, 9, 10
WS_LAW_FLAG_ELASTIC, WS_LAW_FLAG_VISCOUS = 1, 2
WS_LAW_MAX_DIM, WS_LAW_MAX_TERMS, WS_LAW_MAX_PRONY = 6, 16, 16
WS_SPRING_AROUND, WS_SPRING_UP, WS_SPRING_SHEAR = 0, 1, 2
# element.h
WS_ELEMENT_ROD, WS_ELEMENT_LINEAR_SPRING, WS_ELEMENT_ANGULAR_SPRING, WS_ELEMENT_BUSHING = 0, 1, 2, 3
WS_ELEMENT_INVARIANT, WS_ELEMENT_ATTACHED, WS_ELEMENT_POTENTIAL = 0, 1, 2

c_enum = c_int


# --- common.h ------------------------------------------------------------------------------------
class Vec3(Structure):
    _fields_ = [("x", c_double), ("y", c_double), ("z", c_double)]


class Quat(Structure):
    _fields_ = [("e0", c_double), ("e1", c_double), ("e2", c_double), ("e3", c_double)]


class Mat3(Structure):
    _fields_ = [("m", c_double * 9)]


class Pose(Structure):
    _fields_ = [("position", Vec3), ("orientation", Quat)]


class _Id(Structure):
    _fields_ = [("bits", c_uint64)]


class BodyId(_Id):
    pass


class ShapeId(_Id):
    pass


class MaterialId(_Id):
    pass


class LawId(_Id):
    pass


class WebId(_Id):
    pass


class ElementId(_Id):
    pass


AllocFn = CFUNCTYPE(c_void_p, c_void_p, c_size_t)
ReallocFn = CFUNCTYPE(c_void_p, c_void_p, c_void_p, c_size_t, c_size_t)
FreeFn = CFUNCTYPE(None, c_void_p, c_void_p, c_size_t)


class Allocator(Structure):
    _fields_ = [("alloc", AllocFn), ("realloc", ReallocFn), ("free", FreeFn), ("user", c_void_p)]


LogFn = CFUNCTYPE(None, c_void_p, c_enum, c_char_p)


# --- world.h -------------------------------------------------------------------------------------
class WorldDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("gravity", Vec3),
        ("dt", c_double),
        ("integrator", c_enum),
        ("full_detection_until", c_double),
        ("detection_interval", c_int),
        ("contact_margin", c_double),
        ("max_speed", c_double),
        ("max_angular_speed", c_double),
        ("use_ccd", c_int),
        ("profile", c_int),
        ("allocator", Allocator),
        ("log", LogFn),
        ("log_user", c_void_p),
        ("user_data", c_void_p),
        ("stable_fraction", c_double),
        ("worker_count", c_uint32),
        ("enqueue_task", c_void_p),
        ("finish_task", c_void_p),
        ("task_context", c_void_p),
        ("friction_step", c_enum),
    ]


class ContactDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("stiffness", c_double),
        ("damping", c_double),
        ("friction", c_double),
        ("friction_vlim", c_double),
        ("friction_model", c_enum),
        ("stick_stiffness", c_double),
        ("stick_damping", c_double),
        ("stick_damping_ratio", c_double),
    ]


class MaterialDef(Structure):
    _fields_ = [("size", c_uint32), ("magic", c_uint32), ("name", c_char_p)]


class WorldStats(Structure):
    _fields_ = [
        ("time", c_double),
        ("steps", c_uint64),
        ("full_detections", c_uint64),
        ("narrow_checks", c_uint64),
        ("body_pairs_tested", c_uint64),
        ("body_pairs_gated", c_uint64),
        ("contacts", c_uint64),
        ("candidates", c_uint64),
        ("numerical_errors", c_uint64),
        ("bytes_in_use", c_uint64),
        ("bytes_peak", c_uint64),
        ("bodies", c_uint64),
        ("seconds_detection", c_double),
        ("seconds_contacts", c_double),
        ("seconds_web", c_double),
        ("seconds_total", c_double),
        ("web_step_use", c_double),
        ("body_step_use", c_double),
        ("friction_step_use", c_double),
        ("reserved", c_uint64 * 1),
    ]


class Energy(Structure):
    _fields_ = [("kinetic", c_double), ("potential", c_double), ("contact", c_double)]


# --- shape.h -------------------------------------------------------------------------------------
class MeshDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("vertices", POINTER(c_double)),
        ("vertex_count", c_size_t),
        ("triangles", POINTER(c_uint32)),
        ("triangle_count", c_size_t),
    ]


class ShapeInfo(Structure):
    _fields_ = [
        ("volume", c_double),
        ("centroid", Vec3),
        ("aabb_min", Vec3),
        ("aabb_max", Vec3),
        ("inertia_unit", Mat3),
        ("point_count", c_uint32),
        ("edge_count", c_uint32),
        ("face_count", c_uint32),
        ("triangle_count", c_uint32),
        ("convex", c_int),
    ]


# --- body.h --------------------------------------------------------------------------------------
class BodyDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("type", c_enum),
        ("shape", ShapeId),
        ("material", MaterialId),
        ("mass", c_double),
        ("density", c_double),
        ("inertia", Mat3),
        ("contact_layer", c_double),
        ("position", Vec3),
        ("orientation", Quat),
        ("velocity", Vec3),
        ("angular_velocity", Vec3),
        ("name", c_char_p),
        ("user_data", c_void_p),
    ]


DriveFn = CFUNCTYPE(c_int, c_void_p, c_double, POINTER(Pose), POINTER(Vec3), POINTER(Vec3))


class DriveDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("type", c_enum),
        ("start_time", c_double),
        ("ramp_time", c_double),
        ("axis", Vec3),
        ("point", Vec3),
        ("rate", c_double),
        ("max_angle", c_double),
        ("direction", Vec3),
        ("amplitude", c_double),
        ("frequency", c_double),
        ("phase", c_double),
        ("callback", DriveFn),
        ("callback_user", c_void_p),
        # added in 0.2
        ("stop_ramp_time", c_double),
        ("acceleration", c_double),
        ("rise_time", c_double),
        ("hold_time", c_double),
        ("pulse_mode", c_enum),
        ("gentle_acceleration", c_double),
        ("coast_time", c_double),
        ("speed", c_double),
        ("pulse_duration", c_double),
        ("table", POINTER(c_double)),
        ("table_count", c_size_t),
        ("table_interval", c_double),
        ("table_end_at_rest", c_int),
        ("psd_frequency", POINTER(c_double)),
        ("psd_level", POINTER(c_double)),
        ("psd_count", c_size_t),
        ("seed", c_uint64),
        ("duration", c_double),
        ("sample_rate", c_double),
        ("frequency_end", c_double),
        ("sweep_law", c_enum),
    ]


class DriveState(Structure):
    _fields_ = [
        ("time", c_double),
        ("type", c_enum),
        ("position", Vec3),
        ("displacement", Vec3),
        ("velocity", Vec3),
        ("acceleration", Vec3),
        ("angular_velocity", Vec3),
        ("angle", c_double),
        ("angular_rate", c_double),
        ("angular_acceleration", c_double),
        ("has_acceleration", c_int),
    ]


# --- contact.h -----------------------------------------------------------------------------------
class ContactInfo(Structure):
    _fields_ = [
        ("body_a", BodyId),
        ("body_b", BodyId),
        ("point", Vec3),
        ("normal", Vec3),
        ("overlap", c_double),
        ("normal_force", c_double),
        ("friction_force", Vec3),
        ("slip_velocity", Vec3),
        ("kind", c_int32),
        ("slipping", c_int32),
        ("at_cap", c_int32),
        ("reserved_", c_int32),
        ("anchor_deflection", Vec3),
    ]


# --- law.h ---------------------------------------------------------------------------------------
LawTimeFn = CFUNCTYPE(c_int, c_void_p, c_double, POINTER(c_double))
LawUserFn = CFUNCTYPE(c_int, c_void_p, c_int, POINTER(c_double), POINTER(c_double), c_double,
                      POINTER(c_double), POINTER(c_double), POINTER(c_double))


class LawDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("type", c_enum),
        ("stiffness", c_double),
        ("compression_stiffness", c_double),
        ("damping", c_double),
        ("transition", c_double),
        ("name", c_char_p),
        ("dim", c_int),
        ("stiffness_matrix", POINTER(c_double)),
        ("damping_matrix", POINTER(c_double)),
        ("cubic_stiffness", c_double),
        ("cubic_stiffnesses", POINTER(c_double)),
        ("table_strain", POINTER(c_double)),
        ("table_force", POINTER(c_double)),
        ("table_count", c_size_t),
        ("stop_low", c_double),
        ("stop_high", c_double),
        ("prony_stiffness", POINTER(c_double)),
        ("prony_time", POINTER(c_double)),
        ("prony_count", c_size_t),
        ("terms", POINTER(LawId)),
        ("term_count", c_size_t),
        ("base", LawId),
        ("scale", c_double),
        ("scale_times", POINTER(c_double)),
        ("scale_factors", POINTER(c_double)),
        ("scale_count", c_size_t),
        ("scale_fn", LawTimeFn),
        ("scale_user", c_void_p),
        ("user_fn", LawUserFn),
        ("user_data", c_void_p),
        ("user_flags", c_uint),
    ]


class LawInfo(Structure):
    _fields_ = [
        ("type", c_enum),
        ("dim", c_int),
        ("flags", c_uint),
        ("state_size", c_uint32),
        ("users", c_uint32),
        ("max_stiffness", c_double),
        ("max_damping", c_double),
    ]


# --- web.h ---------------------------------------------------------------------------------------
class WebDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("node_mass", c_double),
        ("areal_density", c_double),
        ("contact_layer", c_double),
        ("material", MaterialId),
        ("node_damping", c_double),
        ("law", LawId),
        ("law_cross", LawId),
        ("law_shear", LawId),
        ("substeps", c_int),
        ("name", c_char_p),
        ("rupture_strain", c_double),
        ("integrator", c_int),
        ("solver_tolerance", c_double),
        ("solver_max_iterations", c_int),
        ("preconditioner", c_int),
        ("hold_bodies", c_int),
    ]


class WebSolverStats(Structure):
    _fields_ = [
        ("solves", c_uint64),
        ("iterations", c_uint64),
        ("last_iterations", c_int),
        ("last_residual", c_double),
    ]


class SheetDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("nx", c_int), ("ny", c_int),
        ("origin", Vec3),
        ("axis_x", Vec3), ("axis_y", Vec3),
        ("spacing_x", c_double), ("spacing_y", c_double),
        ("prestretch_x", c_double), ("prestretch_y", c_double),
        ("shear", c_int),
        ("pinned", POINTER(c_uint32)),
        ("pinned_count", c_size_t),
    ]


class BandDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("bodies", POINTER(BodyId)),
        ("body_count", c_size_t),
        ("z_bottom", c_double), ("z_top", c_double),
        ("n_around", c_int), ("n_up", c_int),
        ("prestretch_around", c_double),
        ("prestretch_up", c_double),
        ("gap", c_double),
        ("shear", c_int),
    ]


class WebMeshDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("positions", POINTER(c_double)),
        ("node_count", c_size_t),
        ("node_masses", POINTER(c_double)),
        ("springs", POINTER(c_uint32)),
        ("spring_count", c_size_t),
        ("rest_lengths", POINTER(c_double)),
        ("kinds", POINTER(c_uint8)),
        ("pinned", POINTER(c_uint32)),
        ("pinned_count", c_size_t),
        ("stiffness_scales", POINTER(c_double)),
    ]


class WebInfo(Structure):
    _fields_ = [
        ("node_count", c_uint32),
        ("spring_count", c_uint32),
        ("nx", c_int), ("ny", c_int),
        ("closed", c_int),
        ("substeps", c_int),
        ("mass", c_double),
        ("min_node_mass", c_double),
    ]


class WebRupture(Structure):
    _fields_ = [
        ("rupture_strain", c_double),
        ("broken_count", c_uint32),
        ("broken_last_step", c_uint32),
        ("ruptured", c_int),
        ("first_spring", c_uint32),
        ("first_time", c_double),
        ("first_strain", c_double),
        ("first_position", Vec3),
    ]


class WebPeak(Structure):
    _fields_ = [
        ("found", c_int),
        ("spring", c_uint32),
        ("strain", c_double),
        ("tension", c_double),
        ("node_a", c_uint32),
        ("node_b", c_uint32),
        ("position_a", Vec3),
        ("position_b", Vec3),
    ]


class ContainmentBand(Structure):
    _fields_ = [
        ("z_low", c_double), ("z_high", c_double),
        ("hoop_tension", c_double),
        ("line_load", c_double),
        ("contact_force", c_double),
    ]


# --- io.h ----------------------------------------------------------------------------------------
WS_VTK_COMPRESSED = 0
WS_VTK_BINARY = 1
WS_VTK_ASCII = 2
WS_VTK_DEFAULT_BANDS = 10
WS_VTK_MAX_BANDS = 256


class VtkSeriesDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("directory", c_char_p),
        ("basename", c_char_p),
        ("format", c_int),
        ("frame_stride", c_int),
        ("time_stride", c_double),
        ("springs", c_int),
        ("contacts", c_int),
        ("containment_bands", c_int),
        ("double_precision", c_int),
    ]


# --- element.h -----------------------------------------------------------------------------------
class ElementDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("type", c_enum),
        ("formulation", c_enum),
        ("body1", BodyId),
        ("body2", BodyId),
        ("law", LawId),
        ("point1", Vec3),
        ("point2", Vec3),
        ("frame1", Quat),
        ("frame2", Quat),
        ("global_attachment", c_int),
        ("rest_length", c_double),
        ("name", c_char_p),
        ("user_data", c_void_p),
    ]


class ElementOutput(Structure):
    _fields_ = [
        ("type", c_int32),
        ("dim", c_int32),
        ("strain", c_double * 6),
        ("strain_rate", c_double * 6),
        ("law_force", c_double * 6),
        ("force", Vec3),
        ("moment", Vec3),
        ("moment2", Vec3),
        ("point1", Vec3),
        ("point2", Vec3),
        ("frame", Quat),
        ("energy", c_double),
    ]


# --- loadtest.h ----------------------------------------------------------------------------------
LOAD_MAX_LAYERS = 32
LOADTEST_MAX_EVENTS = 64


class LoadInterface(Structure):
    _fields_ = [
        ("stiffness", c_double), ("damping", c_double), ("friction", c_double),
        ("friction_vlim", c_double), ("friction_model", c_enum),
        ("stick_stiffness", c_double), ("stick_damping", c_double),
    ]


class LoadDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("pallet_size", Vec3), ("pallet_mass", c_double),
        ("carton_size", Vec3), ("carton_mass", c_double),
        ("layers", c_int), ("count_x", c_int), ("count_y", c_int),
        ("pattern", c_enum), ("gap", c_double), ("contact_layer", c_double),
        ("stiffness_rule", c_enum),
        ("carton_carton", LoadInterface), ("carton_pallet", LoadInterface),
        ("pallet_platform", LoadInterface), ("film_carton", LoadInterface),
        ("platform", BodyId), ("platform_material", MaterialId), ("origin", Vec3),
        ("allocator", Allocator),
    ]


class LoadInfo(Structure):
    _fields_ = [
        ("platform", BodyId), ("pallet", BodyId),
        ("carton_material", MaterialId), ("pallet_material", MaterialId),
        ("platform_material", MaterialId), ("film_material", MaterialId),
        ("layers", c_int), ("cartons", c_int),
        ("load_height", c_double), ("pallet_top", c_double), ("total_mass", c_double),
        ("film", WebId),
    ]


class LoadCarton(Structure):
    _fields_ = [
        ("body", BodyId), ("layer", c_int), ("index", c_int), ("ix", c_int), ("iy", c_int),
        ("turned", c_int), ("size", Vec3),
    ]


class LoadCartonState(Structure):
    _fields_ = [
        ("displacement", Vec3), ("horizontal", c_double), ("tilt", c_double),
        ("velocity", Vec3),
    ]


class WrapDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("gauge", c_double), ("modulus", c_double), ("density", c_double), ("layers", c_int),
        ("strain_around", c_double), ("strain_up", c_double), ("z_bottom", c_double),
        ("top_margin", c_double), ("node_pitch", c_double), ("node_mass", c_double),
        ("substeps", c_int),
        ("elongation_at_break", c_double), ("powered_prestretch", c_double),
        ("rupture_strain", c_double), ("integrator", c_int),
    ]


class SpiralWrapDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("width", c_double), ("gauge", c_double), ("modulus", c_double), ("density", c_double),
        ("prestretch", c_double), ("neck_in", c_double), ("load_strain", c_double),
        ("revolutions_bottom", c_double), ("revolutions_top", c_double), ("overlap", c_double),
        ("passes", c_int), ("pallet_lock", c_int), ("lock_height", c_double),
        ("top_margin", c_double), ("rope_revolutions", c_double), ("rope_height", c_double),
        ("top_sheet", c_int), ("top_sheet_gauge", c_double),
        ("node_pitch", c_double), ("node_mass_min", c_double), ("substeps", c_int),
        ("elongation_at_break", c_double), ("rupture_strain", c_double), ("integrator", c_int),
    ]


class LoadContainment(Structure):
    _fields_ = [
        ("z_low", c_double), ("z_high", c_double), ("force", c_double),
        ("hoop_tension", c_double), ("line_load", c_double), ("contact_force", c_double),
        ("rows", c_int),
    ]


class LoadtestInterfaceState(Structure):
    _fields_ = [
        ("normal_force", c_double), ("slip_speed", c_double), ("friction_use", c_double),
        ("contacts", c_int),
    ]


class LoadtestSample(Structure):
    _fields_ = [
        ("time", c_double), ("level", c_double), ("platform_velocity", c_double),
        ("platform_position", c_double), ("cartons", c_size_t),
        ("carton", POINTER(LoadCartonState)), ("layers", c_int),
        ("layer_displacement", POINTER(c_double)), ("interfaces", c_int),
        ("interface", POINTER(LoadtestInterfaceState)),
        ("angle", c_double), ("carton_base", POINTER(LoadtestInterfaceState)),
    ]


SampleFn = CFUNCTYPE(c_int, c_void_p, POINTER(LoadtestSample))


class EumosDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("k", c_double), ("g", c_double), ("rise_time", c_double), ("hold_time", c_double),
        ("mode", c_enum), ("stop_level", c_double), ("coast_time", c_double),
        ("rest_before", c_double), ("rest_after", c_double), ("direction", Vec3),
        ("slip_speed", c_double), ("sample_interval", c_int),
        ("on_sample", SampleFn), ("sample_user", c_void_p),
    ]


class LoadtestEvent(Structure):
    _fields_ = [
        ("type", c_int), ("layer", c_int), ("index", c_int), ("time", c_double),
        ("level", c_double), ("value", c_double),
    ]


class LoadtestCriterion(Structure):
    _fields_ = [("value", c_double), ("limit", c_double), ("pass", c_int)]


class EumosVerdict(Structure):
    _fields_ = [
        ("load_height", c_double), ("elastic", LoadtestCriterion),
        ("permanent", LoadtestCriterion), ("bottom", LoadtestCriterion),
        ("layer_shift", LoadtestCriterion), ("rupture", LoadtestCriterion), ("pass", c_int),
    ]


class EumosResult(Structure):
    _fields_ = [
        ("k", c_double), ("duration", c_double), ("peak_level", c_double),
        ("rise_measured", c_double), ("time_at_level", c_double), ("layers", c_int),
        ("layer_max", c_double * LOAD_MAX_LAYERS),
        ("layer_permanent", c_double * LOAD_MAX_LAYERS),
        ("layer_tilt", c_double * LOAD_MAX_LAYERS),
        ("interface_slip_max", c_double * (LOAD_MAX_LAYERS + 1)),
        ("interface_use_max", c_double * (LOAD_MAX_LAYERS + 1)),
        ("cartons_lost", c_int), ("event_count", c_int), ("events_dropped", c_int),
        ("events", LoadtestEvent * LOADTEST_MAX_EVENTS), ("verdict", EumosVerdict),
        ("containment", ContainmentBand * 3), ("film_peak_strain", c_double),
    ]


class KvalueDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("k_low", c_double), ("k_high", c_double), ("tolerance", c_double),
        ("settle_time", c_double), ("wrap", POINTER(WrapDef)),
        ("spiral", POINTER(SpiralWrapDef)),
    ]


class KvalueResult(Structure):
    _fields_ = [
        ("k_value", c_double), ("k_fail", c_double), ("runs", c_int),
        ("last_pass", EumosResult), ("error", c_char * 256), ("settled", c_int),
        ("settle_taken", c_double),
    ]


LOADTEST_MAX_CHECKS = 8
LOADTEST_RESPONSE_BINS = 48
LOADTEST_TILT, LOADTEST_IMPACT, LOADTEST_RANDOM, LOADTEST_SWEEP = 1, 2, 3, 4


class TiltTestDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("rate", c_double), ("target_angle", c_double), ("max_angle", c_double),
        ("ramp_time", c_double), ("stop_time", c_double), ("hold_time", c_double),
        ("stop_at_failure", c_int), ("after_failure", c_double), ("direction", Vec3),
        ("rest_before", c_double), ("slip_speed", c_double), ("tip_fraction", c_double),
        ("sample_interval", c_int), ("keep_state", c_int),
        ("on_sample", SampleFn), ("sample_user", c_void_p),
    ]


class ImpactTestDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("speed", c_double), ("pulse_duration", c_double), ("gentle_acceleration", c_double),
        ("coast_time", c_double), ("rest_before", c_double), ("rest_after", c_double),
        ("direction", Vec3), ("slip_speed", c_double), ("tip_fraction", c_double),
        ("sample_interval", c_int), ("keep_state", c_int),
        ("on_sample", SampleFn), ("sample_user", c_void_p),
    ]


class VibrationTestDef(Structure):
    _fields_ = [
        ("size", c_uint32), ("magic", c_uint32),
        ("sweep", c_int), ("psd_frequency", POINTER(c_double)),
        ("psd_level", POINTER(c_double)), ("psd_count", c_size_t), ("grms", c_double),
        ("seed", c_uint64), ("sample_rate", c_double), ("sweep_level", c_double),
        ("frequency_start", c_double), ("frequency_end", c_double), ("sweep_law", c_enum),
        ("resonance_min", c_double), ("duration", c_double), ("ramp_time", c_double),
        ("direction", Vec3), ("rest_before", c_double), ("rest_after", c_double),
        ("slip_speed", c_double), ("tip_fraction", c_double), ("sample_interval", c_int),
        ("keep_state", c_int), ("on_sample", SampleFn), ("sample_user", c_void_p),
    ]


class LoadtestCheck(Structure):
    _fields_ = [
        ("id", c_int), ("at_least", c_int), ("value", c_double), ("limit", c_double),
        ("pass", c_int),
    ]


class LoadtestVerdict(Structure):
    _fields_ = [
        ("load_height", c_double), ("count", c_int),
        ("check", LoadtestCheck * LOADTEST_MAX_CHECKS), ("pass", c_int),
    ]


class LoadtestResult(Structure):
    _fields_ = [
        ("kind", c_int), ("duration", c_double), ("peak_level", c_double),
        ("angle_reached", c_double), ("failure_angle", c_double), ("failure_event", c_int),
        ("impact_speed", c_double), ("velocity_change", c_double),
        ("peak_deceleration", c_double), ("grms_delivered", c_double),
        ("grms_target", c_double), ("resonance_frequency", c_double),
        ("resonance_transmissibility", c_double), ("response_bins", c_int),
        ("response_frequency", c_double * LOADTEST_RESPONSE_BINS),
        ("response_transmissibility", c_double * LOADTEST_RESPONSE_BINS),
        ("layers", c_int),
        ("layer_max", c_double * LOAD_MAX_LAYERS),
        ("layer_permanent", c_double * LOAD_MAX_LAYERS),
        ("layer_tilt", c_double * LOAD_MAX_LAYERS),
        ("interface_slip_max", c_double * (LOAD_MAX_LAYERS + 1)),
        ("interface_use_max", c_double * (LOAD_MAX_LAYERS + 1)),
        ("cartons_lost", c_int), ("event_count", c_int), ("events_dropped", c_int),
        ("events", LoadtestEvent * LOADTEST_MAX_EVENTS), ("film_peak_strain", c_double),
        ("verdict", LoadtestVerdict),
    ]


# Opaque handles.
World_p = c_void_p
Series_p = c_void_p
Load_p = c_void_p

P = POINTER
_st = c_enum  # ws_status

#: Every public function of libwrapsim: (name, argtypes, restype).
FUNCTIONS = [
    # common.h
    ("ws_status_string", [c_enum], c_char_p),
    ("ws_version_number", [], c_int),
    ("ws_version_string", [], c_char_p),
    ("ws_build_features", [], c_uint),
    # world.h
    ("ws_world_def_init_sized", [P(WorldDef), c_size_t], None),
    ("ws_contact_def_init_sized", [P(ContactDef), c_size_t], None),
    ("ws_material_def_init_sized", [P(MaterialDef), c_size_t], None),
    ("ws_world_create", [P(WorldDef), P(World_p)], _st),
    ("ws_world_destroy", [World_p], None),
    ("ws_world_step", [World_p], _st),
    ("ws_world_step_n", [World_p, c_int64], _st),
    ("ws_world_get_time", [World_p, P(c_double)], _st),
    ("ws_world_get_dt", [World_p, P(c_double)], _st),
    ("ws_world_set_dt", [World_p, c_double], _st),
    ("ws_world_get_stable_fraction", [World_p, P(c_double)], _st),
    ("ws_world_set_gravity", [World_p, P(Vec3)], _st),
    ("ws_world_get_stats", [World_p, P(WorldStats)], _st),
    ("ws_world_get_energy", [World_p, P(Energy)], _st),
    ("ws_world_get_state_hash", [World_p, P(c_uint64)], _st),
    ("ws_world_last_error", [World_p], c_char_p),
    ("ws_world_get_user_data", [World_p], c_void_p),
    ("ws_world_estimate_stable_dt", [World_p, P(c_double)], _st),
    ("ws_world_get_default_material", [World_p, P(MaterialId)], _st),
    ("ws_material_create", [World_p, P(MaterialDef), P(MaterialId)], _st),
    ("ws_material_is_valid", [World_p, MaterialId], c_int),
    ("ws_world_set_contact", [World_p, MaterialId, MaterialId, P(ContactDef)], _st),
    ("ws_world_get_contact", [World_p, MaterialId, MaterialId, P(ContactDef)], _st),
    ("ws_world_set_default_contact", [World_p, P(ContactDef)], _st),
    # shape.h
    ("ws_mesh_def_init_sized", [P(MeshDef), c_size_t], None),
    ("ws_shape_create_box", [World_p, c_double, c_double, c_double, P(ShapeId)], _st),
    ("ws_shape_create_cylinder", [World_p, c_double, c_double, c_int, P(ShapeId)], _st),
    ("ws_shape_create_mesh", [World_p, P(MeshDef), P(ShapeId)], _st),
    ("ws_shape_destroy", [World_p, ShapeId], _st),
    ("ws_shape_is_valid", [World_p, ShapeId], c_int),
    ("ws_shape_get_info", [World_p, ShapeId, P(ShapeInfo)], _st),
    ("ws_shape_get_centroid_offset", [World_p, ShapeId, P(Vec3)], _st),
    ("ws_shape_copy_mesh", [World_p, ShapeId, P(c_double), c_size_t, P(c_size_t), P(c_uint32),
                            c_size_t, P(c_size_t)], _st),
    # body.h
    ("ws_body_def_init_sized", [P(BodyDef), c_size_t], None),
    ("ws_drive_def_init_sized", [P(DriveDef), c_size_t], None),
    ("ws_body_create", [World_p, P(BodyDef), P(BodyId)], _st),
    ("ws_body_destroy", [World_p, BodyId], _st),
    ("ws_body_is_valid", [World_p, BodyId], c_int),
    ("ws_body_set_drive", [World_p, BodyId, P(DriveDef)], _st),
    ("ws_body_get_drive_state", [World_p, BodyId, P(DriveState)], _st),
    ("ws_vibration_synthesize", [World_p, P(DriveDef), P(c_double), c_size_t], _st),
    ("ws_vibration_grms", [P(c_double), P(c_double), c_size_t, P(c_double)], _st),
    ("ws_vibration_truck_psd", [c_enum, P(c_double), P(c_double), c_size_t, P(c_size_t)], _st),
    ("ws_body_get_type", [World_p, BodyId, P(c_enum)], _st),
    ("ws_body_get_position", [World_p, BodyId, P(Vec3)], _st),
    ("ws_body_get_orientation", [World_p, BodyId, P(Quat)], _st),
    ("ws_body_get_rotation", [World_p, BodyId, P(Mat3)], _st),
    ("ws_body_get_velocity", [World_p, BodyId, P(Vec3)], _st),
    ("ws_body_get_angular_velocity", [World_p, BodyId, P(Vec3)], _st),
    ("ws_body_get_angular_velocity_local", [World_p, BodyId, P(Vec3)], _st),
    ("ws_body_get_point_velocity", [World_p, BodyId, P(Vec3), P(Vec3)], _st),
    ("ws_body_get_world_point", [World_p, BodyId, P(Vec3), P(Vec3)], _st),
    ("ws_body_get_mass", [World_p, BodyId, P(c_double)], _st),
    ("ws_body_get_inertia", [World_p, BodyId, P(Mat3)], _st),
    ("ws_body_get_contact_force", [World_p, BodyId, P(Vec3), P(Vec3)], _st),
    ("ws_body_set_pose", [World_p, BodyId, P(Pose)], _st),
    ("ws_body_set_velocity", [World_p, BodyId, P(Vec3), P(Vec3)], _st),
    ("ws_body_get_name", [World_p, BodyId], c_char_p),
    ("ws_body_get_user_data", [World_p, BodyId], c_void_p),
    ("ws_world_copy_body_ids", [World_p, P(BodyId), c_size_t, P(c_size_t)], _st),
    # contact.h
    ("ws_world_get_contact_count", [World_p, P(c_size_t)], _st),
    ("ws_world_copy_contacts", [World_p, P(ContactInfo), c_size_t, P(c_size_t)], _st),
    ("ws_world_copy_contacts_between", [World_p, BodyId, BodyId, P(ContactInfo), c_size_t,
                                        P(c_size_t)], _st),
    ("ws_world_get_interface_stiffness", [World_p, BodyId, BodyId, P(c_double), P(c_size_t)],
     _st),
    # law.h
    ("ws_law_def_init_sized", [P(LawDef), c_size_t], None),
    ("ws_law_create", [World_p, P(LawDef), P(LawId)], _st),
    ("ws_law_destroy", [World_p, LawId], _st),
    ("ws_law_is_valid", [World_p, LawId], c_int),
    ("ws_law_evaluate", [World_p, LawId, c_double, c_double, P(c_double), P(c_double),
                         P(c_double)], _st),
    ("ws_law_energy", [World_p, LawId, c_double, P(c_double)], _st),
    ("ws_law_get_info", [World_p, LawId, P(LawInfo)], _st),
    ("ws_law_get_state_size", [World_p, LawId, P(c_size_t)], _st),
    ("ws_law_init_state", [World_p, LawId, P(c_double)], _st),
    ("ws_law_evaluate_state", [World_p, LawId, P(c_double), P(c_double), P(c_double), c_double,
                               c_double, P(c_double), P(c_double), P(c_double)], _st),
    ("ws_law_commit_state", [World_p, LawId, P(c_double), P(c_double), P(c_double), c_double,
                             c_double], _st),
    ("ws_law_energy_state", [World_p, LawId, P(c_double), P(c_double), c_double, P(c_double)],
     _st),
    # web.h
    ("ws_web_def_init_sized", [P(WebDef), c_size_t], None),
    ("ws_sheet_def_init_sized", [P(SheetDef), c_size_t], None),
    ("ws_band_def_init_sized", [P(BandDef), c_size_t], None),
    ("ws_web_mesh_def_init_sized", [P(WebMeshDef), c_size_t], None),
    ("ws_web_create_sheet", [World_p, P(WebDef), P(SheetDef), P(WebId)], _st),
    ("ws_web_create_band", [World_p, P(WebDef), P(BandDef), P(WebId)], _st),
    ("ws_web_create_mesh", [World_p, P(WebDef), P(WebMeshDef), P(WebId)], _st),
    ("ws_web_destroy", [World_p, WebId], _st),
    ("ws_web_is_valid", [World_p, WebId], c_int),
    ("ws_web_get_info", [World_p, WebId, P(WebInfo)], _st),
    ("ws_web_get_stable_dt", [World_p, WebId, P(c_double)], _st),
    ("ws_web_set_substeps", [World_p, WebId, c_int], _st),
    ("ws_web_get_solver_stats", [World_p, WebId, P(WebSolverStats)], _st),
    ("ws_web_copy_positions", [World_p, WebId, P(c_double), c_size_t, P(c_size_t)], _st),
    ("ws_web_copy_velocities", [World_p, WebId, P(c_double), c_size_t, P(c_size_t)], _st),
    ("ws_web_copy_contact_forces", [World_p, WebId, P(c_double), c_size_t, P(c_size_t)], _st),
    ("ws_web_copy_springs", [World_p, WebId, P(c_uint32), c_size_t, P(c_size_t)], _st),
    ("ws_web_copy_spring_strains", [World_p, WebId, P(c_double), c_size_t, P(c_size_t)], _st),
    ("ws_web_copy_spring_tensions", [World_p, WebId, P(c_double), c_size_t, P(c_size_t)], _st),
    ("ws_web_get_body_force", [World_p, WebId, BodyId, P(Vec3), P(Vec3)], _st),
    ("ws_web_get_containment", [World_p, WebId, P(ContainmentBand), c_size_t], _st),
    ("ws_web_get_energy", [World_p, WebId, P(c_double), P(c_double), P(c_double)], _st),
    ("ws_web_set_rupture_strain", [World_p, WebId, c_double], _st),
    ("ws_web_get_rupture", [World_p, WebId, P(WebRupture)], _st),
    ("ws_web_copy_broken_springs", [World_p, WebId, P(c_uint32), c_size_t, P(c_size_t)], _st),
    ("ws_web_get_peak_strain", [World_p, WebId, P(WebPeak)], _st),
    # element.h
    ("ws_element_def_init_sized", [P(ElementDef), c_size_t], None),
    ("ws_element_create", [World_p, P(ElementDef), P(ElementId)], _st),
    ("ws_element_destroy", [World_p, ElementId], _st),
    ("ws_element_is_valid", [World_p, ElementId], c_int),
    ("ws_element_get_output", [World_p, ElementId, P(ElementOutput)], _st),
    ("ws_element_get_name", [World_p, ElementId], c_char_p),
    ("ws_element_get_user_data", [World_p, ElementId], c_void_p),
    ("ws_world_copy_element_ids", [World_p, P(ElementId), c_size_t, P(c_size_t)], _st),
    ("ws_world_copy_element_outputs", [World_p, P(ElementOutput), c_size_t, P(c_size_t)], _st),
    ("ws_world_get_element_energy", [World_p, P(c_double)], _st),
    # io.h
    ("ws_world_write_vtp", [World_p, c_char_p], _st),
    ("ws_web_write_vtp", [World_p, WebId, c_char_p], _st),
    ("ws_vtk_series_create", [World_p, c_char_p, c_char_p, P(Series_p)], _st),
    ("ws_vtk_series_def_init_sized", [P(VtkSeriesDef), c_size_t], None),
    ("ws_vtk_series_create_def", [World_p, P(VtkSeriesDef), P(Series_p)], _st),
    ("ws_vtk_series_write_frame", [Series_p], _st),
    ("ws_vtk_series_get_frame_count", [Series_p, P(c_size_t)], _st),
    ("ws_vtk_series_destroy", [Series_p], None),
    ("ws_world_save", [World_p, c_void_p, c_size_t, P(c_size_t)], _st),
    ("ws_world_restore", [World_p, c_void_p, c_size_t], _st),
    ("ws_world_save_file", [World_p, c_char_p], _st),
    ("ws_world_restore_file", [World_p, c_char_p], _st),
    # loadtest.h
    ("ws_load_def_init_sized", [P(LoadDef), c_size_t], None),
    ("ws_load_build", [World_p, P(LoadDef), P(Load_p)], _st),
    ("ws_load_destroy", [Load_p], None),
    ("ws_load_get_info", [Load_p, P(LoadInfo)], _st),
    ("ws_load_get_layer_count", [Load_p, c_int], c_int),
    ("ws_load_get_carton", [Load_p, c_int, c_int, P(LoadCarton)], _st),
    ("ws_load_copy_cartons", [Load_p, P(LoadCarton), c_size_t, P(c_size_t)], _st),
    ("ws_load_get_point_stiffness", [Load_p, c_int, P(c_double), P(c_int)], _st),
    ("ws_load_set_reference", [World_p, Load_p], _st),
    ("ws_load_measure", [World_p, Load_p, P(LoadCartonState), c_size_t, P(c_size_t)], _st),
    ("ws_load_get_drift", [World_p, Load_p, P(c_double)], _st),
    ("ws_load_settle", [World_p, Load_p, c_double, c_double, c_double, P(c_int), P(c_double)],
     _st),
    ("ws_wrap_def_init_sized", [P(WrapDef), c_size_t], None),
    ("ws_load_wrap_band", [World_p, Load_p, P(WrapDef), P(WebId)], _st),
    ("ws_spiral_wrap_def_init_sized", [P(SpiralWrapDef), c_size_t], None),
    ("ws_load_wrap_spiral", [World_p, Load_p, P(SpiralWrapDef), P(WebId)], _st),
    ("ws_spiral_wrap_layers", [P(SpiralWrapDef), c_double, c_double, c_double, c_double,
                               c_double, P(c_int)], _st),
    ("ws_load_get_containment", [World_p, Load_p, P(LoadContainment), c_size_t], _st),
    ("ws_load_get_film_peak", [World_p, Load_p, P(c_double), P(c_uint32), P(c_double)], _st),
    ("ws_eumos_def_init_sized", [P(EumosDef), c_size_t], None),
    ("ws_eumos_get_drive", [P(EumosDef), P(DriveDef), P(c_double)], _st),
    ("ws_loadtest_run_eumos", [World_p, Load_p, P(EumosDef), P(EumosResult)], _st),
    ("ws_kvalue_def_init_sized", [P(KvalueDef), c_size_t], None),
    ("ws_tilt_test_def_init_sized", [P(TiltTestDef), c_size_t], None),
    ("ws_impact_test_def_init_sized", [P(ImpactTestDef), c_size_t], None),
    ("ws_vibration_test_def_init_sized", [P(VibrationTestDef), c_size_t], None),
    ("ws_loadtest_run_tilt", [World_p, Load_p, P(TiltTestDef), P(LoadtestResult)], _st),
    ("ws_loadtest_run_impact", [World_p, Load_p, P(ImpactTestDef), P(LoadtestResult)], _st),
    ("ws_loadtest_run_vibration", [World_p, Load_p, P(VibrationTestDef), P(LoadtestResult)],
     _st),
    ("ws_loadtest_check_name", [c_int], c_char_p),
    ("ws_loadtest_find_k", [P(WorldDef), P(LoadDef), P(EumosDef), P(KvalueDef), P(KvalueResult)],
     _st),
]

#: The Defs and their sized inits (ws_*_def_init_sized(def, size)): the binding passes its
#: struct's ctypes.sizeof, so the library never writes past it, and the size the library records
#: (the bytes both know) is checked against it when loading.
DEF_INITS = [
    ("ws_world_def_init_sized", WorldDef),
    ("ws_contact_def_init_sized", ContactDef),
    ("ws_material_def_init_sized", MaterialDef),
    ("ws_mesh_def_init_sized", MeshDef),
    ("ws_body_def_init_sized", BodyDef),
    ("ws_drive_def_init_sized", DriveDef),
    ("ws_law_def_init_sized", LawDef),
    ("ws_web_def_init_sized", WebDef),
    ("ws_sheet_def_init_sized", SheetDef),
    ("ws_band_def_init_sized", BandDef),
    ("ws_web_mesh_def_init_sized", WebMeshDef),
    ("ws_element_def_init_sized", ElementDef),
    ("ws_vtk_series_def_init_sized", VtkSeriesDef),
    ("ws_tilt_test_def_init_sized", TiltTestDef),
    ("ws_impact_test_def_init_sized", ImpactTestDef),
    ("ws_vibration_test_def_init_sized", VibrationTestDef),
]


class LibraryError(ImportError):
    """libwrapsim could not be found, or is not one this binding can use."""


def _candidates():
    """Where to look for the library, in order: (path or name, how it was found)."""
    env = os.environ.get("WRAPSIM_LIBRARY")
    if env:
        return [(env, "WRAPSIM_LIBRARY")]
    out = []
    names = {"darwin": ["libwrapsim.dylib", "libwrapsim.0.dylib"],
             "win32": ["wrapsim.dll", "libwrapsim.dll"]}.get(sys.platform,
                                                            ["libwrapsim.so.0", "libwrapsim.so"])
    # Installed by pip: the library travels inside the package, next to this module.
    here = pathlib.Path(__file__).resolve().parent
    for name in names:
        p = here / name
        if p.exists():
            out.append((str(p), "the package"))
    # The build tree: <repo>/bindings/python/wrapsim/_lib.py -> <repo>/build/lib.
    repo = here.parents[2]
    for name in names:
        p = repo / "build" / "lib" / name
        if p.exists():
            out.append((str(p), "the build tree"))
    found = ctypes.util.find_library("wrapsim")
    if found:
        out.append((found, "the installed library"))
    out.append((names[0], "the dynamic loader's search path"))
    return out


def _check_defs(lib, path):
    """Refuse a library whose Def structs are smaller than the ones above (fields the binding
    sets would be ignored). The sized init writes no more than the struct's own size."""
    for name, struct in DEF_INITS:
        d = struct()
        getattr(lib, name)(ctypes.byref(d), ctypes.sizeof(struct))
        if d.size != ctypes.sizeof(struct):
            raise LibraryError(
                f"{path}: {name} knows {d.size} bytes of the binding's {struct.__name__} of "
                f"{ctypes.sizeof(struct)}: the library and the binding disagree on the headers")


def load(path=None):
    """Load libwrapsim (from `path`, else WRAPSIM_LIBRARY, the build tree, the installed
    library), declare every function of FUNCTIONS and check the version. Raise LibraryError."""
    tried = []
    cands = [(path, "the path given")] if path else _candidates()
    lib = None
    for cand, how in cands:
        try:
            lib = ctypes.CDLL(cand)
            where = f"{cand} ({how})"
            break
        except OSError as e:
            tried.append(f"{cand} ({how}): {e}")
    if lib is None:
        raise LibraryError("libwrapsim not found; tried:\n  " + "\n  ".join(tried) +
                           "\nInstall the package with the library inside it (from the repository: "
                           "`pip install --no-build-isolation .`), set WRAPSIM_LIBRARY to the path "
                           "of libwrapsim.so.0, or build it with `meson setup build && ninja -C "
                           "build` in the repository.")
    missing = []
    for name, argtypes, restype in FUNCTIONS:
        try:
            fn = getattr(lib, name)
        except AttributeError:
            missing.append(name)
            continue
        fn.argtypes = argtypes
        fn.restype = restype
    if "ws_version_number" in missing:
        raise LibraryError(f"{where} is not libwrapsim (no ws_version_number)")
    version = lib.ws_version_number()
    if version < REQUIRED_VERSION:
        raise LibraryError(
            f"{where} is libwrapsim {lib.ws_version_string().decode()} ({version}); this binding "
            f"needs {REQUIRED_VERSION // 10000}.{REQUIRED_VERSION // 100 % 100}."
            f"{REQUIRED_VERSION % 100} or newer")
    if version // 10000 != REQUIRED_VERSION // 10000:
        raise LibraryError(f"{where} is libwrapsim {lib.ws_version_string().decode()}, another "
                           f"major version than the binding's {BINDING_VERSION}")
    if missing:
        raise LibraryError(f"{where} lacks {', '.join(missing)}")
    _check_defs(lib, where)
    lib._wrapsim_path = where
    return lib


_lib = None


def lib():
    """The loaded library (loaded on first use)."""
    global _lib
    if _lib is None:
        _lib = load()
    return _lib
