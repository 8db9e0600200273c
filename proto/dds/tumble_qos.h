// The QoS of the topics in tumble_states.idl, for the server's writers and for readers that want
// what the server sends (Cyclone DDS's C API). The caller deletes the QoS (dds_delete_qos).
#pragma once

#include <dds/dds.h>

// States (poses, ids, contacts, statistics): the newest wins; a reader that misses one waits for
// the next step.
static inline dds_qos_t* tumble_states_qos(void) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_BEST_EFFORT, 0);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  return qos;
}

// The body catalogue: every body's last sample kept for readers that join later. A reliable
// write waits at most `max_blocking` for a slow reader's acknowledgements.
static inline dds_qos_t* tumble_catalogue_qos(dds_duration_t max_blocking) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, max_blocking);
  dds_qset_durability(qos, DDS_DURABILITY_TRANSIENT_LOCAL);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 1);
  return qos;
}

// ROS 2's default QoS (rmw_qos_profile_default: reliable, volatile, keep last 10), for the topics
// of ROS 2's own types (rt/tf, rt/clock, rt/tumble/markers), so that RViz2's and rclcpp's default
// subscriptions match them. A reliable write waits at most `max_blocking` for a slow reader: past
// it the sample is dropped for that reader, and the world goes on.
static inline dds_qos_t* tumble_ros2_default_qos(dds_duration_t max_blocking) {
  dds_qos_t* qos = dds_create_qos();
  dds_qset_reliability(qos, DDS_RELIABILITY_RELIABLE, max_blocking);
  dds_qset_durability(qos, DDS_DURABILITY_VOLATILE);
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 10);
  return qos;
}
