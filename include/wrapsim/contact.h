/**
 * @file contact.h
 * @brief Contact reports: what touched what in the last step, with which forces.
 */
#ifndef WRAPSIM_CONTACT_H
#define WRAPSIM_CONTACT_H

#include <wrapsim/world.h>

#ifdef __cplusplus
extern "C" {
#endif

/** How a contact was found (Goyal). */
typedef enum ws_contact_kind {
    WS_CONTACT_POINT_FACE = 0, /**< a point of body_b in a face of body_a (eq. 14-15) */
    WS_CONTACT_EDGE_EDGE = 1,  /**< an edge of body_a against an edge of body_b (eq. 16-17) */
    /** A point of body_a in a face of body_b: reported only by ws_world_copy_contacts_between()
     *  when the caller's order puts the owner of the face second. */
    WS_CONTACT_FACE_POINT = 2
} ws_contact_kind;

/** One active contact. The normal points from body_a to body_b; the forces are those on body_b
 *  (body_a gets the opposite).
 *
 *  Which body is body_a depends on the geometry in ws_world_copy_contacts(): it is the owner of
 *  the face (or of the first edge), so between two equal stacked boxes half the reports point up
 *  and half down, and the same box on a plane may be body_a or body_b depending on which body's
 *  corner lies in which face. For a fixed direction ask ws_world_copy_contacts_between().
 *
 *  `point` is at mid-layer: halfway between the point (or edge) and its projection on the face
 *  (or the other edge), i.e. about one layer delta away from either surface. */
typedef struct ws_contact_info {
    ws_body_id body_a; /**< owner of the face, or the first edge */
    ws_body_id body_b; /**< owner of the point, or the second edge */
    ws_vec3 point;          /**< where the force acts, m (mid-layer) */
    ws_vec3 normal;         /**< unit, from a to b */
    double overlap;         /**< layer overlap delta_a + delta_b - distance, m (> 0) */
    double normal_force;    /**< N (>= 0, never pulling) */
    ws_vec3 friction_force; /**< N, tangential */
    ws_vec3 slip_velocity;  /**< tangential velocity of b relative to a, m/s */
    int32_t kind;           /**< ws_contact_kind */
    /** 1 when sliding: |v_t| >= v_lim, under either law (stick: the friction at its cap and
     *  the anchor moving with the slip, not merely held at the cap for a step). */
    int32_t slipping;
    /** 1 when the friction force is at its cap mu N in this step (regularised: |v_t| >= v_lim;
     *  stick: the anchor spring's force was capped and the anchor moved), whether or not the
     *  contact is sliding. */
    int32_t at_cap;
    int32_t reserved_;      /**< zero */
    /** Stick model: the anchor spring's tangential deflection, point of b minus its anchor on
     *  a, m (its force is -stick_stiffness times it, before damping); zero for the regularised
     *  law. */
    ws_vec3 anchor_deflection;
} ws_contact_info;

/** Number of active contacts after the last step. */
WS_API ws_status ws_world_get_contact_count(const ws_world *world, size_t *count);
/** Copy the active contacts. With buf NULL and capacity 0 only the count is written. When
 *  capacity < count, the first `capacity` are copied and WS_ERR_BUFFER_TOO_SMALL returned. */
WS_API ws_status ws_world_copy_contacts(const ws_world *world, ws_contact_info *buf,
                                        size_t capacity, size_t *count);

/** Copy the active contacts between two bodies, in the caller's order: in every report body_a
 *  is `a`, body_b is `b`, the normal points from a to b and the forces and slip velocity are
 *  those of b (a gets the opposite force), whichever body owns the face and whichever was
 *  created first. A point of a in a face of b is reported as WS_CONTACT_FACE_POINT. With buf
 *  NULL and capacity 0 only the count is written; when capacity < count the first `capacity`
 *  are copied and WS_ERR_BUFFER_TOO_SMALL returned.
 *  @return WS_OK, WS_ERR_STALE_HANDLE (a or b), WS_ERR_INVALID_ARGUMENT (a == b, count NULL,
 *          buf NULL with capacity > 0), WS_ERR_BUFFER_TOO_SMALL. */
WS_API ws_status ws_world_copy_contacts_between(const ws_world *world, ws_body_id a,
                                                ws_body_id b, ws_contact_info *buf,
                                                size_t capacity, size_t *count);

/** The normal stiffness of the interface between two bodies as the last step left it: every
 *  active contact point between them is a penalty spring of the pair's stiffness k (N/m) in
 *  parallel, times its share of the pair's laws, so the interface stiffness is k times the
 *  number of supports. A box resting on a larger plane touches it at its 4 corners (4k); two
 *  equal boxes stacked face to face have 8 contacts, each corner of either box lying on the
 *  other's face, but the two at a corner are twins sharing one spring (4k, as when shifted;
 *  see docs/theory.md, "Contact geometry").
 *  @param stiffness  N/m, summed over the active points' shares; 0 when they do not touch
 *  @param points     number of active contact points; may be NULL
 *  @return WS_OK, WS_ERR_STALE_HANDLE (a or b), WS_ERR_INVALID_ARGUMENT (a == b, stiffness
 *          NULL). */
WS_API ws_status ws_world_get_interface_stiffness(const ws_world *world, ws_body_id a,
                                                  ws_body_id b, double *stiffness,
                                                  size_t *points);

#ifdef __cplusplus
}
#endif

#endif
