/* sn_detail.h -- details on the cut level (DETAILS, DETAIL, CELLD, CELLDK;
 * format 6.4; LEVELS.md §3 "Details on the cut level"), internal: level 1's
 * free vertices inside the cut level's cells, each a level-1 hat added to the
 * cut field (the hierarchical basis of seed 000 §3.1), with the cut element's
 * blocks [detail x corner / extra / detail] and their mass (sn_detail.c).
 */
#ifndef SN_DETAIL_H
#define SN_DETAIL_H

#include "sn_instance.h"

/* Validator (sn_blob.c): the table's counts of DETAILS, DETAIL, CELLD,
 * CELLDK and CELLX (the details live on the cut level only). */
sn_status sn_check_details(const sn_view *v, uint32_t nhd, uint32_t nd, uint32_t ncd, uint32_t ndk, uint32_t ncx);

#endif /* SN_DETAIL_H */
