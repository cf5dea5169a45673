/**
 * @file loadtest.h
 * @brief Unit loads (a pallet with layers of cartons) built in one call, and the tests a load
 *        must pass: the EUMOS 40509 acceleration test with its measurements, events, verdict
 *        and k-value search.
 *
 * A load is built in a world with ws_load_build() from a ws_load_def: the pallet, the cartons
 * layer by layer, the materials and the contact parameters of every interface. The returned
 * ws_load (an object outside the world that describes what was built) names the bodies by layer
 * and place, and carries the reference the measurements are taken from. It uses only the public
 * calls of the world underneath, so everything it does can be done by hand.
 *
 * Interface stiffness (docs/guide.md, chapter 11): by default the stiffness and damping of an
 * interface are given for the interface as a whole, as a packaging engineer measures them (the
 * force per metre of compression of one carton bearing on what carries it), and the builder
 * divides them by the number of contact points a face pair of the load touches with: 4, the
 * corners of the smaller face lying in the larger (the builder makes every second layer's
 * cartons 1 mm a side smaller, so that stacked faces are never equal: equal faces put every
 * corner on the other's edge, where a shift of a nanometre drops half the contacts). With
 * WS_LOAD_STIFFNESS_PER_POINT they are taken as they are, per contact point, as
 * ws_contact_def is.
 *
 * Frames: the platform's frame is the frame of the platform body (x along the pallet's length
 * when the platform is created by the builder, z up). Displacements are read relative to the
 * pallet in that frame, which is what EUMOS 40509 measures.
 */
#ifndef WRAPSIM_LOADTEST_H
#define WRAPSIM_LOADTEST_H

#include <wrapsim/body.h>
#include <wrapsim/web.h>
#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Most layers a load may have. */
#define WS_LOAD_MAX_LAYERS 32
/** Most cartons a layer may have. */
#define WS_LOAD_MAX_PER_LAYER 256
/** Most events a test run keeps (later ones are counted in events_dropped). */
#define WS_LOADTEST_MAX_EVENTS 64

/** A load, built in a world. Opaque; destroy with ws_load_destroy(). */
typedef struct ws_load ws_load;

/** How layers are stacked. */
typedef enum ws_load_pattern {
    /** Every layer the same grid: cartons stand on cartons (column stacking). */
    WS_LOAD_COLUMN = 0,
    /** Interlocked as bricks: every second layer's rows are shifted by half a carton along x and
     *  hold one carton fewer, so each of its cartons bridges two below. */
    WS_LOAD_BRICK = 1,
    /** Interlocked by turning: every second layer's cartons are turned 90 degrees about the
     *  vertical, as many along x and y as fit in the footprint of the first layer, centred. */
    WS_LOAD_TURNED = 2
} ws_load_pattern;

/** How an interface's stiffness and damping are read. */
typedef enum ws_load_stiffness_rule {
    /** For the interface as a whole (N/m, kg/s of one face pair), divided by the number of
     *  contact points of a face pair of the load (4: the corners of the smaller face). The
     *  default: no tuning per geometry. */
    WS_LOAD_STIFFNESS_PER_INTERFACE = 0,
    /** Per contact point, as ws_contact_def takes them. */
    WS_LOAD_STIFFNESS_PER_POINT = 1
} ws_load_stiffness_rule;

/** The contact parameters of one interface. Stiffness, damping and the stick model's spring and
 *  damper are read by the load's ws_load_stiffness_rule; the film-carton interface is always per
 *  film node (a node touches at one point). */
typedef struct ws_load_interface {
    double stiffness;       /**< normal stiffness, N/m (> 0) */
    double damping;         /**< normal damping, kg/s (>= 0) */
    double friction;        /**< Coulomb mu (>= 0) */
    double friction_vlim;   /**< regularisation speed, m/s (> 0) */
    ws_friction_model friction_model; /**< default WS_FRICTION_STICK (no creep under a load) */
    double stick_stiffness; /**< tangential spring of the stick model, N/m (> 0) */
    double stick_damping;   /**< tangential damping of the stick model, kg/s (>= 0) */
} ws_load_interface;

/** A unit load: a pallet and layers of equal cartons. Fill with ws_load_def_init(). */
typedef struct ws_load_def {
    uint32_t size;  /**< set by ws_load_def_init() */
    uint32_t magic; /**< set by ws_load_def_init() */
    ws_vec3 pallet_size;  /**< pallet length (x), width (y), height (z), m; default EUR 1.2, 0.8,
                               0.144 */
    double pallet_mass;   /**< kg (> 0); default 25 */
    ws_vec3 carton_size;  /**< carton along x, along y, height, m; default 0.3, 0.4, 0.25 (a
                               400 x 300 x 250 mm carton with its long side across the pallet) */
    double carton_mass;   /**< kg (> 0); default 10 */
    int layers;           /**< 1 .. WS_LOAD_MAX_LAYERS; default 4 */
    int count_x;          /**< cartons along x in the first layer (>= 1); default 4 */
    int count_y;          /**< cartons along y in the first layer (>= 1); default 2 */
    ws_load_pattern pattern; /**< default WS_LOAD_COLUMN */
    /** Clear gap between neighbouring cartons' contact layers, m (>= 0). Cartons stand at the
     *  pitch of their nominal size (a layer of count_x x count_y fills that much of the pallet);
     *  each carton's mesh is smaller than carton_size by 2 contact_layer + gap in x and y (and
     *  every second layer's by another 2 mm, see the top of this file). The
     *  default 0.003 keeps neighbours outside the world's default contact margin (2 mm), so
     *  they cost no contact checks until they move toward each other. */
    double gap;
    double contact_layer; /**< delta of every body of the load, m (>= 0); default 0.001 */
    ws_load_stiffness_rule stiffness_rule; /**< default WS_LOAD_STIFFNESS_PER_INTERFACE */
    /** Carton on carton. Default 2e6 N/m, 2000 kg/s, mu 0.4, stick 2e6 N/m, 2000 kg/s. */
    ws_load_interface carton_carton;
    /** Carton on pallet (and on the platform, for a carton that falls). Default as
     *  carton_carton with mu 0.45. */
    ws_load_interface carton_pallet;
    /** Pallet on platform. Default 2e7 N/m, 2e4 kg/s, mu 0.8, stick 2e7 N/m, 2e4 kg/s. */
    ws_load_interface pallet_platform;
    /** Film on carton and on pallet, per film node. Default 4000 N/m, 1 kg/s, mu 0.9,
     *  regularised with v_lim 0.01 m/s. */
    ws_load_interface film_carton;
    /** The platform to build on, a kinematic body whose top face is level; the null id (default)
     *  creates one: a kinematic box 4 x 2 x 0.1 m with its top face at z = 0 under the pallet's
     *  centre. */
    ws_body_id platform;
    /** The platform's material when `platform` is given (null: the world's default material). */
    ws_material_id platform_material;
    /** Where the pallet's centre of its bottom face goes, m, when the builder creates the
     *  platform: (x, y, 0) of this; with a given platform, the point of its top face the pallet
     *  stands on (the builder cannot read a body's shape: say where). Default (0, 0, 0). */
    ws_vec3 origin;
    /** Allocator hooks for the ws_load object itself; all NULL (default) means malloc. */
    ws_allocator allocator;
} ws_load_def;

/** What a load is, after ws_load_build(). */
typedef struct ws_load_info {
    ws_body_id platform;        /**< the platform (created or given) */
    ws_body_id pallet;          /**< the pallet */
    ws_material_id carton_material;   /**< the cartons' material */
    ws_material_id pallet_material;   /**< the pallet's */
    ws_material_id platform_material; /**< the platform's */
    ws_material_id film_material;     /**< give this to a web that wraps the load */
    int layers;                 /**< number of layers */
    int cartons;                /**< cartons in all */
    double load_height;         /**< from the platform's top face to the top of the load, m */
    double pallet_top;          /**< height of the pallet's deck above the platform's top, m */
    double total_mass;          /**< pallet + cartons, kg */
    ws_web_id film;             /**< the film of ws_load_wrap_band() or ws_load_wrap_spiral();
                                     null when unwrapped */
} ws_load_info;

/** One carton as built. */
typedef struct ws_load_carton {
    ws_body_id body;  /**< its id */
    int layer;        /**< 0 = bottom layer */
    int index;        /**< place in its layer, row-major: index = iy * nx + ix */
    int ix;           /**< column in its layer */
    int iy;           /**< row in its layer */
    int turned;       /**< 1 if turned 90 degrees about the vertical */
    ws_vec3 size;     /**< its extent along the platform's x, y, z, m */
} ws_load_carton;

/** What ws_load_measure() reads of one carton, relative to the reference. */
typedef struct ws_load_carton_state {
    /** Displacement relative to the pallet in the platform's frame since the reference, m. */
    ws_vec3 displacement;
    double horizontal;  /**< |(dx, dy)| of displacement, m */
    double tilt;        /**< angle between its vertical axis and the platform's, rad */
    ws_vec3 velocity;   /**< CoG velocity relative to the pallet, platform frame, m/s */
} ws_load_carton_state;

/** Fill a load Def with the defaults above. NULL is ignored.
 *  ws_load_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_load_def_init_sized(ws_load_def *def, size_t size);
/** The plain form of the init (the whole Def of these headers). New code reaches the macro
 *  below. */
WS_API void(ws_load_def_init)(ws_load_def *def);
/** Fill with defaults: ws_load_def_init_sized with the caller's sizeof. */
#define ws_load_def_init(def) ws_load_def_init_sized((def), sizeof *(def))

/** Build a load in a world: materials (carton, pallet, film; platform when created), the
 *  contact parameters of every pair of them (carton-carton, carton-pallet, carton-platform,
 *  pallet-platform, film-carton, film-pallet), the platform (unless given), the pallet and the
 *  cartons, layer by layer from the bottom, each resting on the one below with the contact layers
 *  just touching. Sets the reference of the measurements (ws_load_set_reference()) to the load
 *  as built.
 *  @param world the world to build in
 *  @param def the load; copied, may be freed after the call
 *  @param out receives the load; destroy it with ws_load_destroy() (the bodies stay in the
 *  world). On error *out is NULL and the bodies already created are destroyed.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a size or mass <= 0, NaN, too many layers or
 *  cartons, a given platform that is not kinematic), WS_ERR_UNINITIALIZED_DEF,
 *  WS_ERR_STALE_HANDLE (platform or its material), WS_ERR_OUT_OF_MEMORY; the detail is in
 *  ws_world_last_error(). */
WS_API ws_status ws_load_build(ws_world *world, const ws_load_def *def, ws_load **out);
/** Free the load object (not its bodies, which belong to the world). NULL does nothing. May be
 *  called after the world is destroyed. */
WS_API void ws_load_destroy(ws_load *load);
/** Counts, ids and heights. @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL). */
WS_API ws_status ws_load_get_info(const ws_load *load, ws_load_info *info);
/** Number of cartons in a layer (0 for a layer out of range). */
WS_API int ws_load_get_layer_count(const ws_load *load, int layer);
/** The carton at (layer, index). @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL or out of range,
 *  with no last error: a load has no world to hold it). */
WS_API ws_status ws_load_get_carton(const ws_load *load, int layer, int index,
                                    ws_load_carton *carton);
/** Copy every carton, bottom layer first, row-major in each layer. buf may be NULL with capacity
 *  0 to ask for the count; WS_ERR_BUFFER_TOO_SMALL when capacity < count (the first `capacity`
 *  are copied). */
WS_API ws_status ws_load_copy_cartons(const ws_load *load, ws_load_carton *buf,
                                      size_t capacity, size_t *count);
/** The contact point stiffness (N/m) the builder gave an interface: 0 carton-carton,
 *  1 carton-pallet, 2 pallet-platform, 3 film-carton; the points per face pair it divided by
 *  (4, or 1 per point and for the film) in *points (may be NULL). */
WS_API ws_status ws_load_get_point_stiffness(const ws_load *load, int interface_kind,
                                             double *stiffness, int *points);

/** Take the load as it stands now as the reference of ws_load_measure(): each carton's position
 *  and orientation relative to the pallet in the platform's frame.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, or a load of another world), WS_ERR_STALE_HANDLE
 *  (a body of the load was destroyed). */
WS_API ws_status ws_load_set_reference(ws_world *world, ws_load *load);
/** Per carton (in the order of ws_load_copy_cartons()): displacement relative to the pallet in
 *  the platform's frame since the reference, tilt, velocity relative to the pallet. Same buffer
 *  rules as ws_load_copy_cartons(). */
WS_API ws_status ws_load_measure(const ws_world *world, const ws_load *load,
                                 ws_load_carton_state *buf, size_t capacity, size_t *count);
/** Largest speed (m/s) of any body of the load (pallet and cartons) relative to the platform's
 *  point under it: its drift. */
WS_API ws_status ws_load_get_drift(const ws_world *world, const ws_load *load, double *speed);
/** Step until the load stands still: at least `min_time` s, then until the drift
 *  (ws_load_get_drift()) stays below `speed` (m/s, > 0) for 0.1 s, or `max_time` s have passed.
 *  *settled (may be NULL) is 1 when it stood still, 0 when max_time ran out; *time_taken (may be
 *  NULL) is the simulated time stepped, s. Errors of the step are returned as they are. */
WS_API ws_status ws_load_settle(ws_world *world, const ws_load *load, double min_time,
                                double max_time, double speed, int *settled, double *time_taken);

/** A band of stretch film around the load: `layers` layers of film everywhere on the band,
 *  laid with an on-load strain, from low on the pallet (the film-to-pallet lock) to near the
 *  top. A simple wrap, not yet a spiral recipe of a machine (no overlaps, roping or top sheet).
 *  Fill with ws_wrap_def_init(). */
typedef struct ws_wrap_def {
    uint32_t size;  /**< set by ws_wrap_def_init() */
    uint32_t magic; /**< set by ws_wrap_def_init() */
    double gauge;         /**< thickness of one film layer, m (> 0); default 20e-6 */
    double modulus;       /**< Young's modulus of the film, Pa (> 0); default 150e6 */
    double density;       /**< of the film, kg/m^3 (> 0); default 920 */
    int layers;           /**< film layers on top of each other (>= 1); default 3 */
    /** Strain the film holds on the load around it, the tension the pre-stretch leaves (> -1,
     *  < 10); default 0.1 */
    double strain_around;
    double strain_up;     /**< the same up the load; default 0.02 */
    /** Lowest row, m above the platform's top (>= 0): below the deck's top the film locks the
     *  load to the pallet. Default 0.03. */
    double z_bottom;
    double top_margin;    /**< the highest row this far below the load's top, m (>= 0);
                               default 0.03 */
    double node_pitch;    /**< node spacing on the load, m (> 0); default 0.05 */
    /** kg per node (>= 0); 0 = the film's real mass (density x gauge x layers x area), which
     *  needs many sub-steps. Default 2e-3: 3.7 kg for the reference load's film, stable at
     *  dt 0.25 ms with 2 sub-steps; its inertia is still small beside the load's. */
    double node_mass;
    /** film sub-steps per world step (>= 1), or 0 (the default): the fewest that the world's
     *  stable-step check accepts (ws_world_get_stable_fraction, ws_web_get_stable_dt) */
    int substeps;
    /* ---- film rupture (trailing fields: older callers get the defaults) ---- */
    /** The film's elongation at break, from its unstretched length (>= 0; 0: the film never
     *  breaks, unless rupture_strain is given). Default 4.0: 400 %, in the middle of LLDPE
     *  stretch film's 300-500 %. */
    double elongation_at_break;
    /** The powered pre-stretch the film got before it was laid, from its unstretched length
     *  (>= 0, below elongation_at_break): the springs' rest length is the film after it.
     *  Default 2.5 (250 %, a machine's pre-stretch carriage); 0 for a hand wrap. */
    double powered_prestretch;
    /** The web's rupture strain (ws_web_def.rupture_strain) when > 0; 0 (the default): from
     *  the two above, (1 + elongation_at_break) / (1 + powered_prestretch) - 1, 0.43 with the
     *  defaults. Must be above strain_around and strain_up (the film would break as it is
     *  laid). */
    double rupture_strain;
    /* ---- the film's integrator (trailing field: older callers get the default) ---- */
    /** ws_web_integrator: WS_WEB_EXPLICIT (the default) or WS_WEB_IMPLICIT, the film at any
     *  node mass in one sub-step (docs/guide.md, "The implicit film"); with node_mass = 0 the
     *  band keeps its real mass, whose inertia matters on a sled, impact or vibration test.
     *  An implicit band takes one sub-step when substeps is 0. */
    int integrator;
} ws_wrap_def;

/** Fill a wrap Def with the defaults above. NULL is ignored.
 *  ws_wrap_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_wrap_def_init_sized(ws_wrap_def *def, size_t size);
/** The plain form of the init (the whole Def of these headers). New code reaches the macro
 *  below. */
WS_API void(ws_wrap_def_init)(ws_wrap_def *def);
/** Fill with defaults: ws_wrap_def_init_sized with the caller's sizeof. */
#define ws_wrap_def_init(def) ws_wrap_def_init_sized((def), sizeof *(def))
/** Wrap a band of film around the load as it stands (ws_web_create_band() around the pallet and
 *  every carton) with the load's film material. The springs follow a tension-compression law
 *  (1 % stiffness in compression: film buckles) of EA = modulus x gauge x layers x the strip
 *  a spring stands for, per unit strain. The platform must be level and its frame the global
 *  one (the band's rows are at global heights).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a bad Def, a load of another world, a load
 *  already wrapped), WS_ERR_UNINITIALIZED_DEF, WS_ERR_OUT_OF_MEMORY, errors of the web's
 *  creation. */
WS_API ws_status ws_load_wrap_band(ws_world *world, ws_load *load, const ws_wrap_def *def,
                                   ws_web_id *out);

/** A spiral wrap as a stretch-wrapping machine lays it (docs/guide.md, chapter 11, and
 *  docs/theory.md, "The spiral wrap"): a film of `width` and `gauge` off the roll, stretched on
 *  the carriage by the powered `prestretch`, which thins it and narrows it by `neck_in`, laid
 *  round the turning load holding the elastic `load_strain`; `revolutions_bottom` at the
 *  bottom, then a spiral up whose revolutions overlap by `overlap` of the laid width,
 *  `revolutions_top` at the top and, with `passes` = 2, the spiral down again. Where revolutions
 *  overlap the film has the stiffness and mass of every layer there. Fill with
 *  ws_spiral_wrap_def_init(). */
typedef struct ws_spiral_wrap_def {
    uint32_t size;  /**< set by ws_spiral_wrap_def_init() */
    uint32_t magic; /**< set by ws_spiral_wrap_def_init() */
    double width;   /**< film width off the roll, m (> 0, <= 10); default 0.5 */
    double gauge;   /**< film thickness off the roll, m (> 0, <= 0.01); default 20e-6 */
    /** Young's modulus of the film as it lies on the load (after the pre-stretch), Pa (> 0,
     *  <= 1e12); default 150e6 */
    double modulus;
    double density;    /**< kg/m^3 (> 0, <= 1e5); default 920 */
    /** Powered pre-stretch, as a fraction: 2.0 is 200 %, a metre off the roll becomes three on
     *  the load (0 .. 10); default 2.0. Plastic: it thins the film (volume kept), it is not the
     *  strain the film holds on the load. */
    double prestretch;
    /** Fraction of the width the pre-stretch takes away (the film necks between the rollers;
     *  0 .. 0.9); default 0.15: a 500 mm film lies 425 mm wide. */
    double neck_in;
    /** The elastic strain the film holds on the load, measured from its pre-stretched length:
     *  the stretch between the carriage's last roller and the load (> 0, < 1); default 0.1. */
    double load_strain;
    double revolutions_bottom; /**< revolutions at the lowest height (>= 0); default 2 */
    double revolutions_top;    /**< revolutions at the highest height (>= 0); default 2 */
    /** Fraction of the laid width by which a revolution of the spiral overlaps the one before
     *  (0 .. 0.95); default 0.5 (every spiral pass lays two layers) */
    double overlap;
    int passes;        /**< 1: spiral up; 2: up and down again; default 2 */
    /** 1 (default): the film's lower edge goes down onto the pallet, `lock_height` above the
     *  platform's top, and locks the load to it; 0: it starts `lock_height` above the deck. */
    int pallet_lock;
    double lock_height; /**< m (>= 0); default 0.05 */
    /** The film's upper edge this far below the top of the load, m (>= 0); default 0.02 */
    double top_margin;
    /** Revolutions of roped film (the width rolled into a cable) at `rope_height` (>= 0);
     *  default 0: no roping */
    double rope_revolutions;
    double rope_height; /**< m above the platform's top (> 0 when roping); default 0.2 */
    /** 1: a top sheet, a loose sheet of film over the top face laid before the top
     *  revolutions, which hold its edges (it joins the film's highest row over the load's top
     *  edges); 0 (default): none */
    int top_sheet;
    /** thickness of the top sheet, m (> 0; it is not pre-stretched); default 50e-6 */
    double top_sheet_gauge;
    /** node spacing on the load, m (> 0, under a quarter of the film's height on the load, and
     *  at most about 1e6 nodes round the pallet); default 0.05 */
    double node_pitch;
    /** Smallest node mass, kg (>= 0): nodes lighter than this (the film's real mass from its
     *  layers) are made this heavy, so fewer sub-steps are stable. Default 0: the real mass. */
    double node_mass_min;
    /** film sub-steps per world step (>= 1), or 0 (the default): the fewest that the world's
     *  stable-step check accepts */
    int substeps;
    /* ---- film rupture (trailing fields: older callers get the defaults) ---- */
    /** The film's elongation at break, from its length off the roll (>= 0; 0: the film never
     *  breaks, unless rupture_strain is given). Default 4.0 (400 %, LLDPE stretch film breaks
     *  at 300-500 %). Must be above `prestretch`. */
    double elongation_at_break;
    /** The web's rupture strain (ws_web_def.rupture_strain) when > 0; 0 (the default): from the
     *  elongation at break and the pre-stretch, (1 + elongation_at_break) / (1 + prestretch) - 1,
     *  0.667 with the defaults; either way above `load_strain` (the film would break as it is
     *  laid). The top sheet, not pre-stretched, takes the same limit: it breaks early, if
     *  ever. */
    double rupture_strain;
    /* ---- the film's integrator (trailing field: older callers get the default) ---- */
    /** ws_web_integrator: WS_WEB_EXPLICIT (the default) or WS_WEB_IMPLICIT, the film at its real
     *  mass (node_mass_min 0, the default) in one sub-step where the explicit film needs
     *  hundreds (docs/guide.md, "The implicit film"). An implicit film takes one sub-step when
     *  substeps is 0. */
    int integrator;
} ws_spiral_wrap_def;

/** Fill a spiral wrap Def with the defaults above. NULL is ignored. */
WS_API void ws_spiral_wrap_def_init_sized(ws_spiral_wrap_def *def, size_t size);
/** The plain form of the init (the whole Def of these headers). */
WS_API void(ws_spiral_wrap_def_init)(ws_spiral_wrap_def *def);
/** Fill with defaults: ws_spiral_wrap_def_init_sized with the caller's sizeof. */
#define ws_spiral_wrap_def_init(def) ws_spiral_wrap_def_init_sized((def), sizeof *(def))

/** Wrap the load as it stands in a spiral of film (the load's film material): one web, a grid
 *  of nodes round the load (rows node_pitch apart or less, following the load's outline at
 *  their height, a node on every vertical corner), each node's mass and each spring's stiffness
 *  the sum over the film layers the spiral lays there (ws_web_mesh_def.stiffness_scales). The
 *  film is laid in equilibrium: each row's around-springs share one tension (the row's mean
 *  layers x E h_l x load_strain a unit height, h_l the laid thickness), the corners' nodes sit
 *  as deep in their contact as that tension presses them, nothing is stretched up the load, so
 *  a load that stood still stands still wrapped. The platform must be level, its frame the
 *  global one; the load's outline at each height is taken as the rectangle of its bodies there
 *  (as ws_load_build makes them).
 *  @param out receives the web (also in ws_load_info.film)
 *  A spiral lays at most 1e4 revolutions (a film narrow for the load's height is refused).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a bad Def: the message names the field, a
 *  load of another world, a load already wrapped), WS_ERR_UNINITIALIZED_DEF, WS_ERR_IN_STEP,
 *  WS_ERR_OUT_OF_MEMORY, errors of the web's creation. */
WS_API ws_status ws_load_wrap_spiral(ws_world *world, ws_load *load,
                                     const ws_spiral_wrap_def *def, ws_web_id *out);
/** The film layers the spiral of `def` lays on a load `height` m high (from the platform's top)
 *  whose deck is at `deck` m, at height z (m above the platform's top) and a place `s` m round
 *  the load's outline of perimeter `perimeter` m from where the film starts (the middle of the
 *  load's face towards -y); roping not counted. A whole number: the revolutions covering it.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a bad Def or geometry), WS_ERR_UNINITIALIZED_DEF. */
WS_API ws_status ws_spiral_wrap_layers(const ws_spiral_wrap_def *def, double height, double deck,
                                       double perimeter, double s, double z, int *layers);

/** The containment of one height band of a wrapped load. */
typedef struct ws_load_containment {
    double z_low;  /**< m above the platform's top, the band's lower bound */
    double z_high; /**< its upper bound */
    /** Containment force, N: how hard the film in the band squeezes the load across its two
     *  vertical mid-planes (through the pallet's centre, along x and along y), from the bodies'
     *  contact forces on the film's nodes: sum over the nodes of (s_x F_x + s_y F_y) / 8, s = +1
     *  on the low side of a plane and -1 on the high side. The film in equilibrium crosses each
     *  plane twice at its hoop tension T, so each plane's squeeze is 2 T from either side and
     *  the force is T: the band's hoop tension, read from what the load feels (the pull-plate
     *  quantity, for the whole band). */
    double force;
    /** The film's own hoop tension across the band, N: the sum over the film's rows in the band
     *  of each row's mean around-spring tension. Equal to `force` when the film is at rest. */
    double hoop_tension;
    double line_load;     /**< force per metre of the band's height, N/m */
    double contact_force; /**< sum of |contact force| on the band's nodes, N */
    int rows;             /**< film rows in the band */
} ws_load_containment;

/** Containment of a wrapped load (ws_load_wrap_band or ws_load_wrap_spiral) in `count` equal
 *  height bands of the load, bottom first (3: bottom, middle, top thirds from the platform's
 *  top to the load's top), from the last step's contact forces and the film's present state.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, count 0 or above 64, a load that is not
 *  wrapped, a load of another world), WS_ERR_STALE_HANDLE (the film destroyed). */
WS_API ws_status ws_load_get_containment(const ws_world *world, const ws_load *load,
                                         ws_load_containment *bands, size_t count);
/** The film's largest strain of an intact spring now (l/l0 - 1; ws_web_get_peak_strain), the
 *  spring's index (ws_web_copy_springs order) and its height (mean of its ends' z, m above the
 *  platform's top); all 0 when no spring is intact. Any output but `strain` may be NULL.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a load that is not wrapped),
 *  WS_ERR_STALE_HANDLE. */
WS_API ws_status ws_load_get_film_peak(const ws_world *world, const ws_load *load,
                                       double *strain, uint32_t *spring, double *height);

/* ---------------------------------------------------------------------------------------- */
/* EUMOS 40509 */

/** One interface of the load, between level i - 1 and level i: interface 0 is pallet on
 *  platform, 1 the bottom layer on the pallet, i layer i - 1 on layer i - 2. */
typedef struct ws_loadtest_interface_state {
    double normal_force;  /**< sum of the contacts' normal forces, N */
    double slip_speed;    /**< normal-force-weighted mean slip speed, m/s */
    double friction_use;  /**< sum |Ft| / (mu sum Fn): 1 when all of it slides */
    int contacts;         /**< contacts in it */
} ws_loadtest_interface_state;

/** A measurement during a run, given to ws_eumos_def.on_sample. Pointers are valid during the
 *  call only. */
typedef struct ws_loadtest_sample {
    double time;          /**< s, from the start of the run */
    /** the platform's acceleration along the direction, in g, as its drive delivered it
     *  (ws_body_get_drive_state()); negative while it brakes */
    double level;
    double platform_velocity; /**< m/s along the direction */
    double platform_position; /**< m along the direction, from where it started */
    size_t cartons;       /**< entries of carton[] */
    const ws_load_carton_state *carton; /**< per carton, as ws_load_measure() */
    int layers;           /**< entries of layer_displacement[] */
    const double *layer_displacement; /**< per layer: mean displacement along the direction, m */
    int interfaces;       /**< entries of interface[] (layers + 1) */
    const ws_loadtest_interface_state *interface; /**< per interface */
    /** Tilt runs: the platform's angle, rad (level is then tan of it); 0 for the others */
    double angle;
    /** Per carton (entries: cartons), the interface under it alone: the normal force, slip
     *  speed and friction use of the contacts that carry it, as interface[] for a layer */
    const ws_loadtest_interface_state *carton_base;
} ws_loadtest_sample;

/** The acceleration test of EUMOS 40509 as the platform's WS_DRIVE_PULSE drive: the platform
 *  accelerates horizontally at k g, reached within 50 ms, held at least 0.3 s, and is then
 *  stopped gently; or, in the run-up-then-brake variant, it runs up gently and brakes at k g.
 *  Fill with ws_eumos_def_init(). */
typedef struct ws_eumos_def {
    uint32_t size;  /**< set by ws_eumos_def_init() */
    uint32_t magic; /**< set by ws_eumos_def_init() */
    double k;                 /**< plateau acceleration in g (> 0, <= 10); default 0.5 */
    /** The g of k g, m/s^2 (> 0); default 9.81, the world's default gravity, so that k compares
     *  with the friction coefficients of the load as the world sees them. */
    double g;
    /** s, the half-cosine rise 0 -> k g and the fall back (> 0; <= 0.05 for the standard);
     *  default 0.04 */
    double rise_time;
    double hold_time;         /**< s at k g (>= 0; >= 0.3 for the standard); default 0.35 */
    ws_pulse_mode mode;       /**< default WS_PULSE_ACCELERATE; WS_PULSE_BRAKE: run up, brake */
    /** The gentle phase (the stop after the pulse, or the run-up before the braking), in g
     *  (> 0): the peak of its raised-cosine acceleration. The run uses min(stop_level, k / 2),
     *  so the gentle phase never pushes the load harder than half the pulse. Default 0.2. */
    double stop_level;
    double coast_time;        /**< s at constant speed between pulse and gentle phase (>= 0);
                                   default 0.1 */
    double rest_before;       /**< s at rest before the drive starts (>= 0); default 0.05 */
    /** s at rest after the platform stands, before the permanent displacement is read (>= 0);
     *  default 0.5 */
    double rest_after;
    ws_vec3 direction;        /**< of the pulse's acceleration, in the platform's frame;
                                   horizontal; normalised; default (1, 0, 0) */
    double slip_speed;        /**< m/s (> 0): an interface whose load-weighted mean slip speed
                                   passes this is slipping (event); default 0.005 */
    int sample_interval;      /**< steps between measurements (>= 1); default 4 */
    /** Called after each measurement with the sample (NULL for none); return non-zero to stop the
     *  run with WS_ERR_CALLBACK. */
    int (*on_sample)(void *user, const ws_loadtest_sample *sample);
    void *sample_user;        /**< passed to on_sample */
} ws_eumos_def;

/** What happened, when. */
typedef enum ws_loadtest_event_type {
    /** An interface began to slip: its mean slip speed passed ws_eumos_def.slip_speed.
     *  layer = the interface's index. */
    WS_LOADTEST_SLIP_ONSET = 0,
    /** A body began to tip: an edge of its base that carried load at the reference carries less
     *  than 1 % of its support force. layer, index name the carton; layer -1 the pallet. */
    WS_LOADTEST_TIP_ONSET = 1,
    /** A carton left the load: its centre left the pallet's footprint or fell by half its
     *  height. */
    WS_LOADTEST_CARTON_LOST = 2,
    /** Film rupture: the first spring of the film broke in the run (ws_web_get_rupture).
     *  layer -1, index the spring, value its strain. Wrapped loads only. */
    WS_LOADTEST_RUPTURE = 3
} ws_loadtest_event_type;

/** An event of a run. */
typedef struct ws_loadtest_event {
    int type;       /**< ws_loadtest_event_type */
    int layer;      /**< see the type */
    int index;      /**< carton in its layer, or -1 */
    double time;    /**< s from the start of the run */
    double level;   /**< platform acceleration along the direction at that time, in g */
    double value;   /**< the figure that passed its bound (m/s, N ...) */
} ws_loadtest_event;

/** One criterion of a verdict. */
typedef struct ws_loadtest_criterion {
    double value; /**< measured, in the unit of the criterion */
    double limit; /**< the bound it must not pass */
    int pass;     /**< 1 if value <= limit (< for layer shift) */
} ws_loadtest_criterion;

/** The verdict of EUMOS 40509 (docs/guide.md names each criterion and how it is read). */
typedef struct ws_eumos_verdict {
    double load_height; /**< H, m: platform top to the top of the load */
    /** Largest horizontal displacement of any carton relative to the pallet during the test, m;
     *  limit 0.10 H. */
    ws_loadtest_criterion elastic;
    /** Largest horizontal displacement of any carton after the stop and rest_after, m; limit
     *  0.05 H. */
    ws_loadtest_criterion permanent;
    /** Largest permanent displacement of a carton with part of it in the lowest 0.2 m of the load
     *  above the pallet, m; limit 0.04 m. */
    ws_loadtest_criterion bottom;
    /** Largest permanent displacement of a layer relative to the layer under it (or the pallet),
     *  layer means, m; limit 0.02 H (strictly less). */
    ws_loadtest_criterion layer_shift;
    /** Film rupture: springs of the film broken by the end of the run (ws_web_get_rupture);
     *  limit 0. */
    ws_loadtest_criterion rupture;
    int pass; /**< 1 if every criterion passes */
} ws_eumos_verdict;

/** Everything a EUMOS run measured. */
typedef struct ws_eumos_result {
    double k;             /**< the level the run used, g */
    double duration;      /**< s simulated */
    /** largest |platform acceleration| along the direction the drive delivered, g */
    double peak_level;
    /** s from the start of the pulse's rise until the delivered |acceleration| first reached
     *  0.99 k g (the standard: within 0.05 s) */
    double rise_measured;
    /** s the delivered |acceleration| stayed within 1 % of k g (the standard: >= 0.3 s) */
    double time_at_level;
    int layers;           /**< entries used in the per-layer arrays */
    double layer_max[WS_LOAD_MAX_LAYERS];       /**< per layer: largest horizontal displacement
                                                     of its cartons during the test, m */
    double layer_permanent[WS_LOAD_MAX_LAYERS]; /**< per layer: largest after the rest, m */
    double layer_tilt[WS_LOAD_MAX_LAYERS];      /**< per layer: largest tilt of its cartons, rad */
    /** per interface (layers + 1): largest slip speed (m/s) and friction use during the run */
    double interface_slip_max[WS_LOAD_MAX_LAYERS + 1];
    double interface_use_max[WS_LOAD_MAX_LAYERS + 1];     /**< see interface_slip_max */
    int cartons_lost;     /**< cartons that left the load */
    int event_count;      /**< events kept in events[] */
    int events_dropped;   /**< events beyond WS_LOADTEST_MAX_EVENTS */
    ws_loadtest_event events[WS_LOADTEST_MAX_EVENTS]; /**< in time order */
    ws_eumos_verdict verdict; /**< the verdict */
    /** Wrapped loads (ws_load_wrap_band()): the film's containment at the start of the run in
     *  three equal height bands, bottom, middle, top (ws_web_get_containment(): hoop tension,
     *  N, line load, N/m, and the bodies' normal force on it, N); zero when unwrapped. */
    ws_containment_band containment[3];
    /** largest strain of an intact spring of the film during the run (0: none); where it is
     *  now: ws_web_get_peak_strain() */
    double film_peak_strain;
} ws_eumos_result;

/** Fill a EUMOS Def with the defaults above. NULL is ignored.
 *  ws_eumos_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_eumos_def_init_sized(ws_eumos_def *def, size_t size);
/** The plain form of the init (the whole Def of these headers). New code reaches the macro
 *  below. */
WS_API void(ws_eumos_def_init)(ws_eumos_def *def);
/** Fill with defaults: ws_eumos_def_init_sized with the caller's sizeof. */
#define ws_eumos_def_init(def) ws_eumos_def_init_sized((def), sizeof *(def))
/** The platform drive a EUMOS run sets (a WS_DRIVE_PULSE along `direction`, given in global
 *  axes for a platform whose frame is the global one, starting at start_time 0: add the world's
 *  time) and the run's duration in s (rest before, the drive, rest after); either output may
 *  be NULL.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (a bad Def; no last error: there is no world),
 *  WS_ERR_UNINITIALIZED_DEF. */
WS_API ws_status ws_eumos_get_drive(const ws_eumos_def *def, ws_drive_def *drive,
                                    double *duration);
/** Run EUMOS 40509 on a load from the world's present state: the platform's drive is replaced by
 *  the pulse (ws_eumos_get_drive()) and set back to static at the end, where the platform
 *  stopped.
 *  The reference of the measurements is taken at the start (ws_load_set_reference()). Fills
 *  *result (events, per-layer and per-interface figures, the verdict).
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a bad Def, a load of another world),
 *  WS_ERR_UNINITIALIZED_DEF, WS_ERR_STALE_HANDLE, WS_ERR_OUT_OF_MEMORY, errors of the step
 *  (WS_ERR_NUMERICAL) and WS_ERR_CALLBACK (on_sample stopped it); the detail is in
 *  ws_world_last_error(). */
WS_API ws_status ws_loadtest_run_eumos(ws_world *world, ws_load *load, const ws_eumos_def *def,
                                       ws_eumos_result *result);

/** The k-value search. Fill with ws_kvalue_def_init(). */
typedef struct ws_kvalue_def {
    uint32_t size;  /**< set by ws_kvalue_def_init() */
    uint32_t magic; /**< set by ws_kvalue_def_init() */
    double k_low;      /**< lowest k tried, g (> 0); default 0.05 */
    double k_high;     /**< highest k tried, g (> k_low); default 1.0 */
    double tolerance;  /**< the search stops when the bracket is narrower, g (> 0); default 0.01 */
    /** Longest time the fresh load settles before the runs, s (> 0): it steps until the load
     *  stands still (ws_load_settle(): drift under 0.1 mm/s for 0.1 s, after at least 0.2 s or
     *  settle_time if shorter) or this time has passed; default 4.0 (the spiral-wrapped EUR
     *  load needs about 2.2 s after its wrap). */
    double settle_time;
    /** A wrap to put on the load after it settled (it then settles again, as long at most,
     *  before the state is saved); NULL (default) for the load unwrapped. Read during the call
     *  only. */
    const ws_wrap_def *wrap;
    /** A spiral wrap (ws_load_wrap_spiral()) to put on the load after it settled, when `wrap`
     *  is NULL; NULL (default) for none. Read during the call only. */
    const ws_spiral_wrap_def *spiral;
} ws_kvalue_def;

/** What the k-value search found. */
typedef struct ws_kvalue_result {
    double k_value;   /**< the largest k the load passed, g (0 if it failed at k_low) */
    double k_fail;    /**< the smallest k it failed at, g (0 if it passed k_high) */
    int runs;         /**< EUMOS runs made */
    ws_eumos_result last_pass; /**< the run at k_value (zero when none passed) */
    char error[256];  /**< the world's last error when a run failed, else "" */
    /** 1 when the load (and the wrapped load) stood still before the runs; 0 when settle_time
     *  ran out first (the runs then start from a load still moving) */
    int settled;
    double settle_taken; /**< s the load settled, in all (unwrapped and wrapped) */
} ws_kvalue_result;

/** Fill a k-value Def with the defaults above. NULL is ignored.
 *  ws_kvalue_def_init(def) calls this with size = sizeof *def as the caller compiled it
 *  (see "Defs" in common.h). */
WS_API void ws_kvalue_def_init_sized(ws_kvalue_def *def, size_t size);
/** The plain form of the init (the whole Def of these headers). New code reaches the macro
 *  below. */
WS_API void(ws_kvalue_def_init)(ws_kvalue_def *def);
/** Fill with defaults: ws_kvalue_def_init_sized with the caller's sizeof. */
#define ws_kvalue_def_init(def) ws_kvalue_def_init_sized((def), sizeof *(def))
/** Find the load's k-value: the largest k at which it passes EUMOS 40509, by bisection between
 *  k_low and k_high. Every run starts from the same settled load: a world is created from
 *  `world_def`, the load built from `load_def` and settled until it stands still, at most
 *  settle_time (then wrapped and settled again when def->wrap or def->spiral is given), and its
 *  state saved
 *  (ws_world_save()); each run restores it (ws_world_restore()) and runs EUMOS at its k with the
 *  rest of `eumos_def`, so each starts from the same state to the bit.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT, WS_ERR_UNINITIALIZED_DEF, and any error of a run (its
 *  text in result->error). */
WS_API ws_status ws_loadtest_find_k(const ws_world_def *world_def, const ws_load_def *load_def,
                                    const ws_eumos_def *eumos_def, const ws_kvalue_def *def,
                                    ws_kvalue_result *result);

/* ---------------------------------------------------------------------------------------- */
/* Tilt, horizontal impact, random vibration and sine sweep */

/** Most criteria a verdict of ws_loadtest_result holds. */
#define WS_LOADTEST_MAX_CHECKS 8
/** Frequency bins of a sweep's response (ws_loadtest_result.response_*). */
#define WS_LOADTEST_RESPONSE_BINS 48

/** Which test a ws_loadtest_result is of. */
typedef enum ws_loadtest_kind {
    WS_LOADTEST_TILT = 1,    /**< ISO 10531 tilt (ws_loadtest_run_tilt) */
    WS_LOADTEST_IMPACT = 2,  /**< horizontal impact (ws_loadtest_run_impact) */
    WS_LOADTEST_RANDOM = 3,  /**< random vibration (ws_loadtest_run_vibration) */
    WS_LOADTEST_SWEEP = 4    /**< sine sweep (ws_loadtest_run_vibration) */
} ws_loadtest_kind;

/** What a criterion of a ws_loadtest_verdict measures (ws_loadtest_check_name() gives its name;
 *  docs/guide.md, chapter 11, its basis). */
typedef enum ws_loadtest_check_id {
    /** Tilt: the angle (rad) at the first failure event (a slip onset, a tip onset, a carton
     *  leaving the load), or the largest angle reached when none came; at least the target. */
    WS_CHECK_STABLE_ANGLE = 1,
    /** Cartons that left the load; at most 0. */
    WS_CHECK_CARTONS_LOST = 2,
    /** Largest horizontal displacement of any carton relative to the pallet after the run and
     *  its rest, m; at most 0.05 H (EUMOS 40509's permanent limit). */
    WS_CHECK_PERMANENT = 3,
    /** Largest shift of a layer's mean relative to the layer under it after the run, m; less
     *  than 0.02 H (EUMOS 40509's layer limit). */
    WS_CHECK_LAYER_SHIFT = 4,
    /** Impact: |delivered velocity change - speed| / speed; at most 0.01. */
    WS_CHECK_VELOCITY_CHANGE = 5,
    /** Random: |delivered Grms - target| / target over the untapered part; at most 0.10 (a
     *  run of seconds samples its history's Grms with a scatter of a few percent) */
    WS_CHECK_GRMS = 6,
    /** Sweep: the resonance found, Hz; at least the Def's resonance_min. */
    WS_CHECK_RESONANCE = 7,
    /** Wrapped loads: springs of the film broken by the end of the run (ws_web_get_rupture);
     *  at most 0. */
    WS_CHECK_RUPTURE = 8
} ws_loadtest_check_id;

/** One criterion of a verdict: what it measures, the measured value, the limit and pass. */
typedef struct ws_loadtest_check {
    int id;         /**< ws_loadtest_check_id */
    /** 1: the value must be at least the limit; 0: at most the limit (less than it for
     *  WS_CHECK_LAYER_SHIFT) */
    int at_least;
    double value;   /**< measured, in the unit of the criterion */
    double limit;   /**< its bound */
    int pass;       /**< 1 if it passes */
} ws_loadtest_check;

/** The verdict of a tilt, impact or vibration run. */
typedef struct ws_loadtest_verdict {
    double load_height;  /**< H, m: platform top to the top of the load */
    int count;           /**< criteria in check[] */
    ws_loadtest_check check[WS_LOADTEST_MAX_CHECKS]; /**< in the order of the test's table */
    int pass;            /**< 1 if every criterion passes */
} ws_loadtest_verdict;

/** Everything a tilt, impact or vibration run measured. Levels are the drive's: the platform's
 *  acceleration along the drive's direction in g, or on the tilt tan theta (the along-platform
 *  share of gravity over the normal one, which takes the place of a/g). */
typedef struct ws_loadtest_result {
    int kind;              /**< ws_loadtest_kind */
    double duration;       /**< s simulated */
    double peak_level;     /**< largest |level| at the samples */
    /** Tilt: the largest angle reached, rad */
    double angle_reached;
    /** Tilt: the angle (rad) at the first failure event, or -1 when none came */
    double failure_angle;
    /** Tilt: index in events[] of the first failure event, or -1 */
    int failure_event;
    /** Impact: the platform's speed as the programmer's pulse began, m/s */
    double impact_speed;
    /** Impact: the velocity change the pulse delivered, m/s: the integral of the delivered
     *  acceleration over the pulse (trapezoids at every step) */
    double velocity_change;
    /** Impact: the largest deceleration delivered at the steps, g */
    double peak_deceleration;
    /** Random: the Grms the platform delivered over the untapered part (every step), g */
    double grms_delivered;
    double grms_target;    /**< random: the Grms asked, g */
    /** Sweep: the load's resonance, Hz: where the top layer's transmissibility peaks (0 when
     *  the sweep found no peak inside its band) */
    double resonance_frequency;
    /** Sweep: the top layer's transmissibility there (its vertical velocity amplitude over the
     *  platform's, as the acceleration ratio for a steady sine) */
    double resonance_transmissibility;
    /** Sweep: bins of the response, equal ratios from f1 to f2 (entries used) */
    int response_bins;
    double response_frequency[WS_LOADTEST_RESPONSE_BINS];        /**< bin centres, Hz */
    double response_transmissibility[WS_LOADTEST_RESPONSE_BINS]; /**< top layer, per bin */
    int layers;            /**< entries used in the per-layer arrays */
    double layer_max[WS_LOAD_MAX_LAYERS];       /**< per layer: largest horizontal displacement of
                                                     its cartons during the run, m */
    double layer_permanent[WS_LOAD_MAX_LAYERS]; /**< per layer: largest at the end, m */
    double layer_tilt[WS_LOAD_MAX_LAYERS];      /**< per layer: largest tilt, rad */
    double interface_slip_max[WS_LOAD_MAX_LAYERS + 1]; /**< per interface: largest slip speed */
    double interface_use_max[WS_LOAD_MAX_LAYERS + 1];  /**< per interface: largest friction use */
    int cartons_lost;      /**< cartons that left the load */
    int event_count;       /**< events kept in events[] */
    int events_dropped;    /**< events beyond WS_LOADTEST_MAX_EVENTS */
    ws_loadtest_event events[WS_LOADTEST_MAX_EVENTS]; /**< in time order */
    /** largest strain of an intact spring of the film (0: unwrapped) */
    double film_peak_strain;
    ws_loadtest_verdict verdict; /**< the verdict */
} ws_loadtest_result;

/** The name of a criterion ("stable_angle", "cartons_lost" ...; "unknown" for another id):
 *  static text. */
WS_API const char *ws_loadtest_check_name(int id);

/** ISO 10531 tilt: the platform turns about a horizontal axis in its top face at `rate` from
 *  level, smoothly (the rate ramped in over ramp_time), to max_angle, where it stops smoothly
 *  and holds; the run ends hold_time after it stands, or after_failure after the first failure
 *  event when stop_at_failure is set. Fill with ws_tilt_test_def_init(). */
typedef struct ws_tilt_test_def {
    uint32_t size;  /**< set by ws_tilt_test_def_init() */
    uint32_t magic; /**< set by ws_tilt_test_def_init() */
    /** rad/s (> 0, <= 1, and at most 1e4 s to max_angle); default 0.05 (2.9 degrees a
     *  second) */
    double rate;
    /** rad (> 0, < pi/2): the load must stand to this angle; default atan(0.5), 26.6 degrees,
     *  where tan theta equals EUMOS 40509's 0.5 g */
    double target_angle;
    /** rad (>= target_angle, < pi/2), where the platform stops; 0 (default): target_angle */
    double max_angle;
    double ramp_time;    /**< s (>= 0) of the smooth start; default 0.5 */
    double stop_time;    /**< s (>= 0) of the smooth stop at max_angle; default 1.0 */
    double hold_time;    /**< s (>= 0) at max_angle; default 0.5 */
    int stop_at_failure; /**< 1 (default): end after_failure s after the first failure event */
    double after_failure; /**< s (>= 0); default 0.5 */
    /** Downhill, in the platform's frame, horizontal; normalised; default (1, 0, 0). The axis
     *  runs along the top face of the platform under the pallet's centre, across it. */
    ws_vec3 direction;
    double rest_before;   /**< s at rest before the tilt starts (>= 0); default 0.05 */
    /** m/s (> 0): an interface whose load-weighted mean slip speed passes this is slipping;
     *  default 0.0002: past tan theta = mu a box gains slip speed as g rate t^2 / (2 cos
     *  theta), so at the default rate the event falls 0.5 % of tan theta after the onset; the
     *  stick springs' stretch before it moves a load at about 1e-5 m/s */
    double slip_speed;
    /** Tip onset: an edge of a base that carried load now carries less than this share of its
     *  body's support (> 0, < 0.5); default 0.001 */
    double tip_fraction;
    int sample_interval;  /**< steps between measurements (>= 1); default 4 */
    /** 0 (default): the world is restored to the state it had before the run (ws_world_save /
     *  ws_world_restore), the platform static; 1: it is left as the run ended */
    int keep_state;
    /** Called after each measurement (NULL for none); non-zero stops the run (WS_ERR_CALLBACK) */
    int (*on_sample)(void *user, const ws_loadtest_sample *sample);
    void *sample_user;    /**< passed to on_sample */
} ws_tilt_test_def;

/** Horizontal impact (ASTM D4003 / D5414, ISTA 3E): the platform runs up gently to `speed`,
 *  coasts, and is stopped by a programmer: a half-sine deceleration of pulse_duration whose
 *  velocity change is `speed` (WS_DRIVE_IMPACT); then rest. Fill with
 *  ws_impact_test_def_init(). */
typedef struct ws_impact_test_def {
    uint32_t size;  /**< set by ws_impact_test_def_init() */
    uint32_t magic; /**< set by ws_impact_test_def_init() */
    double speed;          /**< m/s at impact (> 0, <= 20); default 1.2 (e.g. 1.2 or 1.75) */
    double pulse_duration; /**< s of the half-sine (> 0, <= 1); default 0.01 */
    /** Peak of the gentle run-up's acceleration, m/s^2 (> 0, <= 100, and a run-up of at most
     *  1e4 s); default 2 (0.2 g): the run-up takes 2 speed / this */
    double gentle_acceleration;
    double coast_time;     /**< s at speed before the impact (>= 0); default 0.2 */
    double rest_before;    /**< s (>= 0); default 0.05 */
    double rest_after;     /**< s after the impact before the permanent state (>= 0); 0.5 */
    /** The platform's travel, in its frame, horizontal; normalised; default (1, 0, 0): the
     *  load is thrown towards +direction when the platform stops */
    ws_vec3 direction;
    double slip_speed;     /**< m/s (> 0), slip onset; default 0.005 */
    double tip_fraction;   /**< tip onset share (> 0, < 0.5); default 0.01 */
    int sample_interval;   /**< steps (>= 1); default 4 */
    int keep_state;        /**< as ws_tilt_test_def; default 0 (restored) */
    int (*on_sample)(void *user, const ws_loadtest_sample *sample); /**< as the tilt's */
    void *sample_user;     /**< passed to on_sample */
} ws_impact_test_def;

/** Random vibration (ASTM D4169 truck, ISTA) or a sine sweep on the platform, vertical by
 *  default. Fill with ws_vibration_test_def_init(). */
typedef struct ws_vibration_test_def {
    uint32_t size;  /**< set by ws_vibration_test_def_init() */
    uint32_t magic; /**< set by ws_vibration_test_def_init() */
    int sweep;      /**< 0 (default): random vibration; 1: sine sweep */
    /** Random: PSD breakpoints (Hz, g^2/Hz), copied; NULL (default): the library's truck
     *  spectrum (ws_vibration_truck_psd) */
    const double *psd_frequency;
    const double *psd_level;  /**< random: g^2/Hz, with psd_frequency */
    size_t psd_count;         /**< random: breakpoints (2 .. 10000) */
    /** Random: the Grms to play, g (>= 0): the PSD is scaled to it; 0 plays the PSD as given.
     *  Default 0.54 (the D4169 truck's medium level; 0.40 and 0.70 are the others) */
    double grms;
    uint64_t seed;            /**< random: the same seed, the same history; default 1 */
    double sample_rate;       /**< random: Hz (> 2 x the top breakpoint); default 1024 */
    /** Sweep: acceleration amplitude, g (> 0); default 0.25 */
    double sweep_level;
    double frequency_start;   /**< sweep: Hz (> 0); default 2 */
    double frequency_end;     /**< sweep: Hz (> frequency_start); default 40 */
    ws_sweep_law sweep_law;   /**< sweep: default WS_SWEEP_LOG */
    /** Sweep: the resonance must be at least this, Hz (>= 0); default 0 (reported only). Set it
     *  to keep the load's resonance above a vehicle's strong band. */
    double resonance_min;
    double duration;          /**< s played (> 0); default 10 */
    double ramp_time;         /**< s of the taper or fade at both ends (>= 0); default 0.5 */
    /** Of the shaking, in the platform's frame; normalised; default (0, 0, 1), vertical */
    ws_vec3 direction;
    double rest_before;       /**< s (>= 0); default 0.05 */
    double rest_after;        /**< s (>= 0); default 0.5 */
    double slip_speed;        /**< m/s (> 0), slip onset; default 0.005 */
    double tip_fraction;      /**< tip onset share (> 0, < 0.5); default 0.01 */
    int sample_interval;      /**< steps (>= 1); default 4 */
    int keep_state;           /**< as ws_tilt_test_def; default 0 (restored) */
    int (*on_sample)(void *user, const ws_loadtest_sample *sample); /**< as the tilt's */
    void *sample_user;        /**< passed to on_sample */
} ws_vibration_test_def;

/** Fill a tilt test Def with the defaults above (NULL is ignored). */
WS_API void ws_tilt_test_def_init_sized(ws_tilt_test_def *def, size_t size);
/** The plain form of the init. */
WS_API void(ws_tilt_test_def_init)(ws_tilt_test_def *def);
/** Fill with defaults: ws_tilt_test_def_init_sized with the caller's sizeof. */
#define ws_tilt_test_def_init(def) ws_tilt_test_def_init_sized((def), sizeof *(def))
/** Fill an impact test Def with the defaults above (NULL is ignored). */
WS_API void ws_impact_test_def_init_sized(ws_impact_test_def *def, size_t size);
/** The plain form of the init. */
WS_API void(ws_impact_test_def_init)(ws_impact_test_def *def);
/** Fill with defaults: ws_impact_test_def_init_sized with the caller's sizeof. */
#define ws_impact_test_def_init(def) ws_impact_test_def_init_sized((def), sizeof *(def))
/** Fill a vibration test Def with the defaults above (NULL is ignored). */
WS_API void ws_vibration_test_def_init_sized(ws_vibration_test_def *def, size_t size);
/** The plain form of the init. */
WS_API void(ws_vibration_test_def_init)(ws_vibration_test_def *def);
/** Fill with defaults: ws_vibration_test_def_init_sized with the caller's sizeof. */
#define ws_vibration_test_def_init(def) ws_vibration_test_def_init_sized((def), sizeof *(def))

/** Run the ISO 10531 tilt on a load from the world's present state, with the measurements and
 *  events of EUMOS (the level is tan theta) and the verdict: WS_CHECK_STABLE_ANGLE (the angle
 *  at the first failure event, at least target_angle), WS_CHECK_CARTONS_LOST. The world is
 *  restored at the end unless keep_state (the platform's drive is then static either way).
 *  The platform must have no drive, or a static one: the run drives it.
 *  @return WS_OK, WS_ERR_INVALID_ARGUMENT (NULL, a bad Def, a load of another world, a driven
 *  platform), WS_ERR_UNINITIALIZED_DEF, WS_ERR_STALE_HANDLE, WS_ERR_IN_STEP,
 *  WS_ERR_OUT_OF_MEMORY, errors of the step and WS_ERR_CALLBACK; the detail is in
 *  ws_world_last_error(). On an error the world is restored too when it can be. */
WS_API ws_status ws_loadtest_run_tilt(ws_world *world, ws_load *load, const ws_tilt_test_def *def,
                                      ws_loadtest_result *result);
/** Run a horizontal impact on a load from the world's present state: the velocity change the
 *  programmer delivered (velocity_change, peak_deceleration) and the verdict:
 *  WS_CHECK_VELOCITY_CHANGE, WS_CHECK_PERMANENT, WS_CHECK_LAYER_SHIFT, WS_CHECK_CARTONS_LOST.
 *  The world is restored at the end unless keep_state. Errors as ws_loadtest_run_tilt(). */
WS_API ws_status ws_loadtest_run_impact(ws_world *world, ws_load *load,
                                        const ws_impact_test_def *def,
                                        ws_loadtest_result *result);
/** Run random vibration (the Grms delivered) or a sine sweep (the top layer's transmissibility
 *  by frequency and the resonance) on a load from the world's present state, and the verdict:
 *  random WS_CHECK_GRMS, WS_CHECK_LAYER_SHIFT, WS_CHECK_CARTONS_LOST; sweep WS_CHECK_RESONANCE,
 *  WS_CHECK_LAYER_SHIFT, WS_CHECK_CARTONS_LOST. The world is restored at the end unless
 *  keep_state. Errors as ws_loadtest_run_tilt(). */
WS_API ws_status ws_loadtest_run_vibration(ws_world *world, ws_load *load,
                                           const ws_vibration_test_def *def,
                                           ws_loadtest_result *result);

#ifdef __cplusplus
}
#endif

#endif
