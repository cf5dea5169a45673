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
    WS_CONTACT_EDGE_EDGE = 1   /**< an edge of body_a against an edge of body_b (eq. 16-17) */
} ws_contact_kind;

/** One active contact. The normal points from body_a to body_b; the forces are those on body_b
 *  (body_a gets the opposite). */
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

#ifdef __cplusplus
}
#endif

#endif
