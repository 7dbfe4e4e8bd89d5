#include "base/agree.h"

#include <stdio.h>
#include <string.h>

int sp_mpi_error(int mpi_code, const char *call) {
  char text[MPI_MAX_ERROR_STRING] = "";
  int len = 0;
  if (MPI_Error_string(mpi_code, text, &len) != MPI_SUCCESS)
    snprintf(text, sizeof text, "MPI error code %d", mpi_code);
  return sp_error_set(SP_ERR_MPI, "MPI: %s failed: %s", call, text);
}

int sp_agree_comm_create(MPI_Comm comm, MPI_Comm *out) {
  *out = MPI_COMM_NULL;
  SP_MPI_CALL(MPI_Comm_dup(comm, out));
  SP_MPI_CALL(MPI_Comm_set_errhandler(*out, MPI_ERRORS_RETURN));
  return SP_OK;
}

void sp_agree_comm_free(MPI_Comm *comm) {
  if (*comm != MPI_COMM_NULL) MPI_Comm_free(comm);
  *comm = MPI_COMM_NULL;
}

int sp_agree(MPI_Comm comm, int rc) {
  if (rc != SP_OK && sp_error_agreed()) return rc; /* known to every rank */
  int size = 1, rank = 0;
  SP_MPI_CALL(MPI_Comm_size(comm, &size));
  SP_MPI_CALL(MPI_Comm_rank(comm, &rank));
  int mine = rc != SP_OK ? rank : size, first = mine;
  if (size > 1) SP_MPI_CALL(MPI_Allreduce(&mine, &first, 1, MPI_INT, MPI_MIN, comm));
  if (first == size) return SP_OK;
  /* the lowest failing rank tells the others what failed */
  int code = rc;
  char text[SP_ERROR_MESSAGE_MAX];
  snprintf(text, sizeof text, "%s", sp_error_message());
  if (size > 1) {
    SP_MPI_CALL(MPI_Bcast(&code, 1, MPI_INT, first, comm));
    SP_MPI_CALL(MPI_Bcast(text, (int)sizeof text, MPI_CHAR, first, comm));
  }
  if (rc != SP_OK) { /* this rank's own error (the same as the first's: adopted) */
    sp_error_mark_agreed(rank != first && code == rc && strcmp(text, sp_error_message()) == 0);
    return rc;
  }
  sp_error_set(code, "on rank %d of %d: %s", first, size, text);
  sp_error_mark_agreed(1);
  return code;
}

int sp_agree_any(MPI_Comm comm, int *flag) {
  SP_CALL(sp_agree(comm, SP_OK));
  int any = *flag != 0;
  SP_MPI_CALL(MPI_Allreduce(MPI_IN_PLACE, &any, 1, MPI_INT, MPI_MAX, comm));
  *flag = any;
  return SP_OK;
}
